// The PLY header: "ply", a format line, then elements with their properties, up to
// "end_header". Comments and obj_info lines are skipped; anything else is an error, since
// a header we misread would decode the body as garbage.
#include <charconv>
#include <string>
#include <vector>

#include "fvs/geometry/ply_format.h"
#include "fvs/util/error.h"

namespace fvs::ply_internal {

bool ParsePlyType(const std::string& name, PlyType* type) {
  struct Entry {
    const char* name;
    PlyType type;
  };
  static const Entry kTypes[] = {
      {"char", PlyType::kInt8},      {"int8", PlyType::kInt8},
      {"uchar", PlyType::kUint8},    {"uint8", PlyType::kUint8},
      {"short", PlyType::kInt16},    {"int16", PlyType::kInt16},
      {"ushort", PlyType::kUint16},  {"uint16", PlyType::kUint16},
      {"int", PlyType::kInt32},      {"int32", PlyType::kInt32},
      {"uint", PlyType::kUint32},    {"uint32", PlyType::kUint32},
      {"float", PlyType::kFloat32},  {"float32", PlyType::kFloat32},
      {"double", PlyType::kFloat64}, {"float64", PlyType::kFloat64},
  };
  for (const Entry& e : kTypes) {
    if (name == e.name) {
      *type = e.type;
      return true;
    }
  }
  return false;
}

int TypeSize(PlyType type) {
  switch (type) {
    case PlyType::kInt8:
    case PlyType::kUint8:
      return 1;
    case PlyType::kInt16:
    case PlyType::kUint16:
      return 2;
    case PlyType::kInt32:
    case PlyType::kUint32:
    case PlyType::kFloat32:
      return 4;
    case PlyType::kFloat64:
      return 8;
  }
  return 1;
}

namespace {

std::vector<std::string> Tokens(const std::string& line) {
  std::vector<std::string> tokens;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t') ++j;
    if (j > i) tokens.push_back(line.substr(i, j - i));
    i = j;
  }
  return tokens;
}

}  // namespace

PlyHeader ParsePlyHeader(const std::string& path, const std::string& data) {
  if (data.size() < 4 || data.compare(0, 3, "ply") != 0 ||
      (data[3] != '\n' && data[3] != '\r')) {
    throw Error(path, "not a PLY file (wrong magic: it does not start with \"ply\")");
  }
  PlyHeader header;
  bool have_format = false;
  size_t pos = 0;
  int line_number = 0;
  while (true) {
    if (pos >= data.size()) {
      throw Error(path, "bad PLY header: no end_header line (truncated file?)");
    }
    size_t eol = data.find('\n', pos);
    if (eol == std::string::npos) {
      throw Error(path, "bad PLY header: no end_header line (truncated file?)");
    }
    std::string line = data.substr(pos, eol - pos);
    pos = eol + 1;
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line_number == 1) continue;  // the magic
    const std::vector<std::string> tokens = Tokens(line);
    auto bad = [&](const std::string& why) {
      throw Error(path, "bad PLY header line " + std::to_string(line_number) + " '" +
                            line.substr(0, 80) + "': " + why);
    };
    if (tokens.empty()) continue;
    const std::string& keyword = tokens[0];
    if (keyword == "comment" || keyword == "obj_info") continue;
    if (keyword == "end_header") break;
    if (keyword == "format") {
      if (tokens.size() != 3) bad("expected 'format <encoding> 1.0'");
      if (tokens[1] == "ascii") {
        header.encoding = Encoding::kAscii;
      } else if (tokens[1] == "binary_little_endian") {
        header.encoding = Encoding::kBinaryLittleEndian;
      } else if (tokens[1] == "binary_big_endian") {
        header.encoding = Encoding::kBinaryBigEndian;
      } else {
        bad("unknown encoding '" + tokens[1] + "'");
      }
      if (tokens[2] != "1.0" && tokens[2] != "1") bad("unsupported version " + tokens[2]);
      have_format = true;
    } else if (keyword == "element") {
      if (tokens.size() != 3) bad("expected 'element <name> <count>'");
      PlyElement element;
      element.name = tokens[1];
      const std::string& c = tokens[2];
      const auto [end, ec] =
          std::from_chars(c.data(), c.data() + c.size(), element.count);
      if (ec != std::errc() || end != c.data() + c.size()) bad("bad element count");
      header.elements.push_back(element);
    } else if (keyword == "property") {
      if (header.elements.empty()) bad("property before any element");
      PlyProperty property;
      if (tokens.size() == 5 && tokens[1] == "list") {
        property.is_list = true;
        if (!ParsePlyType(tokens[2], &property.count_type))
          bad("unknown type " + tokens[2]);
        if (!ParsePlyType(tokens[3], &property.type)) bad("unknown type " + tokens[3]);
        if (property.count_type == PlyType::kFloat32 ||
            property.count_type == PlyType::kFloat64) {
          bad("list count type must be an integer type");
        }
        property.name = tokens[4];
      } else if (tokens.size() == 3 && tokens[1] != "list") {
        if (!ParsePlyType(tokens[1], &property.type)) bad("unknown type " + tokens[1]);
        property.name = tokens[2];
      } else {
        bad("expected 'property <type> <name>' or 'property list <type> <type> <name>'");
      }
      header.elements.back().properties.push_back(property);
    } else {
      bad("unknown keyword '" + keyword + "'");
    }
  }
  if (!have_format) throw Error(path, "bad PLY header: no format line");
  header.body_offset = pos;
  return header;
}

}  // namespace fvs::ply_internal
