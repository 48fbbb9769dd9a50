#pragma once

#include <string>
#include <vector>

namespace fvs {

std::vector<std::string> SplitString(const std::string& s, const std::string& delims);
std::string TrimString(const std::string& s);
bool StartsWith(const std::string& s, const std::string& prefix);
bool EndsWith(const std::string& s, const std::string& suffix);
// Joins path parts with '/' (no normalisation).
std::string JoinPaths(const std::string& a, const std::string& b);

}  // namespace fvs
