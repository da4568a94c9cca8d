// PLY and OBJ triangle meshes for previews (preview.h, LoadMesh).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "brdf/core/error.h"
#include "brdf/core/file_util.h"
#include "brdf/preview/preview.h"
#include "preview_internal.h"

namespace brdf::preview {
namespace {

constexpr std::uint64_t kMaxMeshFileBytes = 512ull << 20;
constexpr std::size_t kMaxElements = 50'000'000;

bool EndsWith(const std::string& s, const std::string& suffix) {
  if (s.size() < suffix.size()) return false;
  return std::equal(suffix.rbegin(), suffix.rend(), s.rbegin(),
                    [](char a, char b) { return std::tolower(a) == std::tolower(b); });
}

// Area-weighted vertex normals from the faces (when the file has none).
void ComputeNormals(Mesh* mesh) {
  mesh->normals.assign(mesh->positions.size(), Vec3{0, 0, 0});
  for (const auto& t : mesh->triangles) {
    const Vec3& a = mesh->positions[t[0]];
    const Vec3 n = detail::Cross(mesh->positions[t[1]] - a, mesh->positions[t[2]] - a);
    for (std::uint32_t v : t) mesh->normals[v] = mesh->normals[v] + n;
  }
  for (Vec3& n : mesh->normals) {
    const double len = detail::Length(n);
    n = len > 0.0 ? n * (1.0 / len) : Vec3{0, 0, 1};
  }
}

void AddPolygon(Mesh* mesh, const std::vector<std::uint32_t>& indices, const std::string& path,
                const std::string& position) {
  if (indices.size() < 3)
    throw FormatError(path, position, "a face of at least 3 vertices",
                      std::to_string(indices.size()) + " vertices");
  for (std::uint32_t i : indices)
    if (i >= mesh->positions.size())
      throw FormatError(
          path, position,
          "vertex indices below the vertex count " + std::to_string(mesh->positions.size()),
          "index " + std::to_string(i));
  for (std::size_t k = 1; k + 1 < indices.size(); ++k)
    mesh->triangles.push_back({indices[0], indices[k], indices[k + 1]});
  if (mesh->triangles.size() > kMaxElements)
    throw FormatError(path, position, "at most 50,000,000 triangles", "more");
}

// OBJ: "v x y z", "vn x y z", "f a/b/c ..." (1-based, negative = relative). Normals are
// attached to vertices by the first face corner that names one.
Mesh ParseObj(const std::string& text, const std::string& path) {
  Mesh mesh;
  std::vector<Vec3> file_normals;
  std::vector<int> normal_of_vertex;
  std::istringstream lines(text);
  std::string line;
  for (std::uint64_t n = 1; std::getline(lines, line); ++n) {
    std::istringstream in(line);
    std::string tag;
    if (!(in >> tag) || tag[0] == '#') continue;
    if (tag == "v" || tag == "vn") {
      Vec3 v;
      if (!(in >> v.x >> v.y >> v.z) || !std::isfinite(v.x) || !std::isfinite(v.y) ||
          !std::isfinite(v.z))
        throw FormatError(path, LinePosition(n), "three finite numbers after '" + tag + "'",
                          "'" + line + "'");
      if (tag == "v") {
        mesh.positions.push_back(v);
        normal_of_vertex.push_back(-1);
        if (mesh.positions.size() > kMaxElements)
          throw FormatError(path, LinePosition(n), "at most 50,000,000 vertices", "more");
      } else {
        file_normals.push_back(v);
      }
    } else if (tag == "f") {
      std::vector<std::uint32_t> indices;
      std::string corner;
      while (in >> corner) {
        long long vi = 0, ni = 0;
        const std::size_t slash1 = corner.find('/');
        try {
          vi = std::stoll(corner.substr(0, slash1));
          if (slash1 != std::string::npos) {
            const std::size_t slash2 = corner.find('/', slash1 + 1);
            if (slash2 != std::string::npos && slash2 + 1 < corner.size())
              ni = std::stoll(corner.substr(slash2 + 1));
          }
        } catch (const std::exception&) {
          throw FormatError(path, LinePosition(n), "face corners 'v', 'v/t' or 'v/t/n'",
                            "'" + corner + "'");
        }
        const long long count = static_cast<long long>(mesh.positions.size());
        const long long v = vi < 0 ? count + vi : vi - 1;
        if (v < 0 || v >= count)
          throw FormatError(path, LinePosition(n),
                            "a vertex index between 1 and " + std::to_string(count),
                            "'" + corner + "'");
        if (ni != 0) {
          const long long nc = static_cast<long long>(file_normals.size());
          const long long k = ni < 0 ? nc + ni : ni - 1;
          if (k < 0 || k >= nc)
            throw FormatError(path, LinePosition(n),
                              "a normal index between 1 and " + std::to_string(nc),
                              "'" + corner + "'");
          if (normal_of_vertex[v] < 0) normal_of_vertex[v] = static_cast<int>(k);
        }
        indices.push_back(static_cast<std::uint32_t>(v));
      }
      AddPolygon(&mesh, indices, path, LinePosition(n));
    }
  }
  const bool all_normals =
      !normal_of_vertex.empty() &&
      std::all_of(normal_of_vertex.begin(), normal_of_vertex.end(), [](int k) { return k >= 0; });
  if (all_normals) {
    mesh.normals.resize(mesh.positions.size());
    for (std::size_t v = 0; v < mesh.positions.size(); ++v)
      mesh.normals[v] = Normalize(file_normals[normal_of_vertex[v]]);
  }
  return mesh;
}

struct PlyProperty {
  std::string name, type, count_type;  // count_type non-empty for lists
};
struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

std::size_t PlyTypeSize(const std::string& t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "float" || t == "int32" || t == "uint32" || t == "float32")
    return 4;
  if (t == "double" || t == "float64") return 8;
  return 0;
}

double ReadBinary(const unsigned char* p, const std::string& t) {
  auto get = [p](auto value) {
    std::memcpy(&value, p, sizeof(value));
    return static_cast<double>(value);
  };
  if (t == "char" || t == "int8") return get(std::int8_t{});
  if (t == "uchar" || t == "uint8") return get(std::uint8_t{});
  if (t == "short" || t == "int16") return get(std::int16_t{});
  if (t == "ushort" || t == "uint16") return get(std::uint16_t{});
  if (t == "int" || t == "int32") return get(std::int32_t{});
  if (t == "uint" || t == "uint32") return get(std::uint32_t{});
  if (t == "float" || t == "float32") return get(float{});
  return get(double{});
}

Mesh ParsePly(const std::string& data, const std::string& path) {
  std::size_t pos = 0;
  std::uint64_t line_number = 0;
  auto next_line = [&](std::string* line) {
    if (pos >= data.size()) return false;
    const std::size_t end = data.find('\n', pos);
    *line = data.substr(pos, end == std::string::npos ? std::string::npos : end - pos);
    if (!line->empty() && line->back() == '\r') line->pop_back();
    pos = end == std::string::npos ? data.size() : end + 1;
    ++line_number;
    return true;
  };
  std::string line;
  if (!next_line(&line) || line != "ply")
    throw FormatError(path, "line 1", "'ply'", "'" + line.substr(0, 40) + "'");
  std::string format;
  std::vector<PlyElement> elements;
  while (true) {
    if (!next_line(&line))
      throw FormatError(path, LinePosition(line_number), "'end_header'", "end of file");
    std::istringstream in(line);
    std::string tag;
    in >> tag;
    if (tag == "end_header") break;
    if (tag == "format") {
      in >> format;
      if (format != "ascii" && format != "binary_little_endian")
        throw FormatError(path, LinePosition(line_number), "format ascii or binary_little_endian",
                          "'" + format + "'");
    } else if (tag == "element") {
      PlyElement e;
      if (!(in >> e.name >> e.count) || e.count > kMaxElements)
        throw FormatError(path, LinePosition(line_number),
                          "'element NAME COUNT' with COUNT ≤ 50,000,000", "'" + line + "'");
      elements.push_back(e);
    } else if (tag == "property") {
      if (elements.empty())
        throw FormatError(path, LinePosition(line_number), "'element' before 'property'",
                          "'" + line + "'");
      PlyProperty p;
      std::string type;
      in >> type;
      if (type == "list") {
        in >> p.count_type >> p.type >> p.name;
        if (PlyTypeSize(p.count_type) == 0 || PlyTypeSize(p.type) == 0)
          throw FormatError(path, LinePosition(line_number), "a list of known types",
                            "'" + line + "'");
      } else {
        p.type = type;
        in >> p.name;
        if (PlyTypeSize(p.type) == 0)
          throw FormatError(path, LinePosition(line_number),
                            "a property type (char, uchar, short, ushort, int, uint, float, "
                            "double)",
                            "'" + type + "'");
      }
      elements.back().properties.push_back(p);
    }
  }
  if (format.empty()) throw FormatError(path, "header", "a 'format' line", "none");
  const bool binary = format == "binary_little_endian";
  Mesh mesh;
  bool has_normals = false;
  std::istringstream ascii(binary ? std::string() : data.substr(pos));
  for (const PlyElement& e : elements) {
    const bool vertex = e.name == "vertex", face = e.name == "face";
    int ix = -1, iy = -1, iz = -1, inx = -1, iny = -1, inz = -1;
    for (int k = 0; k < static_cast<int>(e.properties.size()); ++k) {
      const std::string& n = e.properties[k].name;
      if (n == "x") ix = k;
      if (n == "y") iy = k;
      if (n == "z") iz = k;
      if (n == "nx") inx = k;
      if (n == "ny") iny = k;
      if (n == "nz") inz = k;
    }
    if (vertex && (ix < 0 || iy < 0 || iz < 0))
      throw FormatError(path, "header", "vertex properties x, y, z", "missing");
    if (vertex) has_normals = inx >= 0 && iny >= 0 && inz >= 0;
    for (std::uint64_t item = 0; item < e.count; ++item) {
      std::vector<double> scalars(e.properties.size(), 0.0);
      std::vector<std::uint32_t> list;
      for (std::size_t k = 0; k < e.properties.size(); ++k) {
        const PlyProperty& p = e.properties[k];
        const std::string where =
            binary ? BytePosition(pos) : "element '" + e.name + "' " + std::to_string(item);
        auto read_one = [&](const std::string& type) {
          double v = 0;
          if (binary) {
            const std::size_t size = PlyTypeSize(type);
            if (pos + size > data.size())
              throw FormatError(path, BytePosition(pos), e.name + " " + std::to_string(item),
                                "end of file");
            v = ReadBinary(reinterpret_cast<const unsigned char*>(data.data()) + pos, type);
            pos += size;
          } else if (!(ascii >> v)) {
            throw FormatError(path, where, "a number for '" + p.name + "'", "end or text");
          }
          return v;
        };
        if (p.count_type.empty()) {
          scalars[k] = read_one(p.type);
        } else {
          const double count = read_one(p.count_type);
          if (!(count >= 0 && count <= 1024))
            throw FormatError(path, where, "a list length in [0, 1024]", std::to_string(count));
          for (int c = 0; c < static_cast<int>(count); ++c) {
            const double v = read_one(p.type);
            if (!(v >= 0 && v < 4294967296.0))
              throw FormatError(path, where, "a vertex index ≥ 0", std::to_string(v));
            list.push_back(static_cast<std::uint32_t>(v));
          }
        }
      }
      if (vertex) {
        const Vec3 v = {scalars[ix], scalars[iy], scalars[iz]};
        if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
          throw FormatError(path, "vertex " + std::to_string(item), "finite coordinates",
                            "a NaN or infinity");
        mesh.positions.push_back(v);
        if (has_normals) mesh.normals.push_back(Vec3{scalars[inx], scalars[iny], scalars[inz]});
      } else if (face) {
        AddPolygon(&mesh, list, path, "face " + std::to_string(item));
      }
    }
  }
  if (has_normals)
    for (Vec3& n : mesh.normals) {
      const double len = detail::Length(n);
      n = len > 0.0 && std::isfinite(len) ? n * (1.0 / len) : Vec3{0, 0, 1};
    }
  return mesh;
}

}  // namespace

Mesh LoadMesh(const std::string& path) {
  const std::string data = ReadFileText(path, kMaxMeshFileBytes);
  Mesh mesh;
  if (EndsWith(path, ".obj")) {
    mesh = ParseObj(data, path);
  } else if (EndsWith(path, ".ply")) {
    mesh = ParsePly(data, path);
  } else {
    throw InvalidArgument(path + ": expected a .ply or .obj mesh");
  }
  if (mesh.triangles.empty()) throw FormatError(path, "faces", "at least one triangle", "none");
  if (mesh.normals.size() != mesh.positions.size()) ComputeNormals(&mesh);
  return mesh;
}

}  // namespace brdf::preview
