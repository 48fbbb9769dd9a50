// A 64-bit content hash (FNV-1a over 8-byte words, then a splitmix64 finaliser) for cache
// keys: which weights, which photo. Not cryptographic; fast (one pass over 8-byte words).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace fvs {

uint64_t Hash64(const void* data, size_t bytes, uint64_t seed = 0);
// Hash64 of a file's bytes (the weights' hash of the feature store). Throws fvs::Error
// naming the file when it cannot be read.
uint64_t HashFile(const std::string& path, uint64_t seed = 0);
// 16 lower-case hex digits.
std::string HexHash(uint64_t hash);

}  // namespace fvs
