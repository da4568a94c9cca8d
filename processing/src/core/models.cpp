#include "brdf/core/models.h"

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "brdf/core/error.h"

namespace brdf {
namespace {

struct ModelInfo {
  Model model;
  std::string_view name;
  // JSON member names of kd, ks and shape; empty when the model has no such parameter.
  std::string_view kd, ks, shape;
};

constexpr ModelInfo kModels[] = {
    {Model::kLambert, "lambert", "rho", "", ""},
    {Model::kLafortune, "lafortune", "kd", "ks", "n"},
    {Model::kBlinnPhong, "blinn-phong", "kd", "ks", "n"},
    {Model::kGgx, "ggx", "kd", "f0", "alpha"},
    {Model::kWard, "ward", "rho_d", "rho_s", "alpha"},
};

const ModelInfo& InfoOf(Model model) {
  for (const auto& info : kModels)
    if (info.model == model) return info;
  return kModels[0];
}

std::string KnownModelNames() {
  std::string names;
  for (const auto& info : kModels) {
    if (!names.empty()) names += ", ";
    names += info.name;
  }
  return names;
}

std::string Abbreviate(const nlohmann::json& value) {
  std::string text = value.dump();
  if (text.size() > 60) text = text.substr(0, 57) + "...";
  return text;
}

Rgb ReadRgb(const nlohmann::json& object, std::string_view key, const std::string& file) {
  const std::string member(key);
  const auto it = object.find(member);
  if (it == object.end())
    throw FormatError(file, "member '" + member + "'", "a number or an [r, g, b] array",
                      "nothing (the member is missing)");
  Rgb out{};
  auto read_number = [&](const nlohmann::json& v, const std::string& where) {
    if (!v.is_number()) throw FormatError(file, where, "a finite number", Abbreviate(v));
    const double d = v.get<double>();
    if (!std::isfinite(d)) throw FormatError(file, where, "a finite number", Abbreviate(v));
    return d;
  };
  if (it->is_number()) {
    const double d = read_number(*it, "member '" + member + "'");
    out = {d, d, d};
  } else if (it->is_array() && it->size() == 3) {
    for (int c = 0; c < 3; ++c)
      out[c] = read_number((*it)[c], "member '" + member + "'[" + std::to_string(c) + "]");
  } else {
    throw FormatError(file, "member '" + member + "'", "a number or an [r, g, b] array",
                      Abbreviate(*it));
  }
  return out;
}

nlohmann::json RgbJson(const Rgb& v) {
  if (v[0] == v[1] && v[1] == v[2]) return v[0];
  return nlohmann::json::array({v[0], v[1], v[2]});
}

}  // namespace

std::string_view ModelName(Model model) { return InfoOf(model).name; }

Model ModelFromName(std::string_view name) {
  for (const auto& info : kModels)
    if (info.name == name) return info.model;
  throw InvalidArgument("unknown BRDF model '" + std::string(name) +
                        "' (known: " + KnownModelNames() + ")");
}

Material ParseMaterialJson(std::string_view json_text, const std::string& file) {
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(json_text.begin(), json_text.end());
  } catch (const nlohmann::json::parse_error& e) {
    throw FormatError(file, BytePosition(e.byte), "valid JSON",
                      std::string("a syntax error: ") + e.what());
  }
  if (!doc.is_object())
    throw FormatError(file, "top level", "a JSON object with a \"model\" member",
                      std::string(doc.type_name()));
  const auto model_it = doc.find("model");
  if (model_it == doc.end() || !model_it->is_string())
    throw FormatError(
        file, "member 'model'", "one of " + KnownModelNames(),
        model_it == doc.end() ? "nothing (the member is missing)" : Abbreviate(*model_it));
  Material m;
  try {
    m.model = ModelFromName(model_it->get<std::string>());
  } catch (const InvalidArgument&) {
    throw FormatError(file, "member 'model'", "one of " + KnownModelNames(), Abbreviate(*model_it));
  }
  const ModelInfo& info = InfoOf(m.model);
  m.kd = ReadRgb(doc, info.kd, file);
  if (!info.ks.empty()) m.ks = ReadRgb(doc, info.ks, file);
  if (!info.shape.empty()) m.shape = ReadRgb(doc, info.shape, file);

  nlohmann::json extra = nlohmann::json::object();
  for (auto it = doc.begin(); it != doc.end(); ++it) {
    const std::string& key = it.key();
    if (key == "model" || key == info.kd || key == info.ks || key == info.shape) continue;
    if (key == "name" || key == "description") {
      if (!it->is_string())
        throw FormatError(file, "member '" + key + "'", "a string", Abbreviate(*it));
      (key == "name" ? m.name : m.description) = it->get<std::string>();
      continue;
    }
    extra[key] = *it;
  }
  m.extra_json = extra.dump();
  for (int c = 0; c < 3; ++c) {
    if (!info.shape.empty() && !(m.shape[c] > 0.0))
      throw FormatError(file, "member '" + std::string(info.shape) + "'",
                        "a positive value in every channel", std::to_string(m.shape[c]));
  }
  return m;
}

Material LoadMaterialFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path + ": cannot open material file");
  std::ostringstream text;
  text << in.rdbuf();
  Material m = ParseMaterialJson(text.str(), path);
  if (m.name.empty()) {
    std::string stem = path;
    if (auto slash = stem.find_last_of('/'); slash != std::string::npos)
      stem = stem.substr(slash + 1);
    if (auto dot = stem.rfind('.'); dot != std::string::npos) stem = stem.substr(0, dot);
    m.name = stem;
  }
  return m;
}

std::string MaterialToJson(const Material& material) {
  const ModelInfo& info = InfoOf(material.model);
  nlohmann::ordered_json doc;
  if (!material.name.empty()) doc["name"] = material.name;
  if (!material.description.empty()) doc["description"] = material.description;
  doc["model"] = info.name;
  doc[std::string(info.kd)] = RgbJson(material.kd);
  if (!info.ks.empty()) doc[std::string(info.ks)] = RgbJson(material.ks);
  if (!info.shape.empty()) doc[std::string(info.shape)] = RgbJson(material.shape);
  const auto extra = nlohmann::json::parse(material.extra_json, nullptr, false);
  if (extra.is_object())
    for (auto it = extra.begin(); it != extra.end(); ++it) doc[it.key()] = *it;
  return doc.dump(2) + "\n";
}

std::vector<std::string> PhysicalProblems(const Material& material) {
  std::vector<std::string> problems;
  const ModelInfo& info = InfoOf(material.model);
  static const char* kChannel[] = {"red", "green", "blue"};
  for (int c = 0; c < 3; ++c) {
    const std::string ch = kChannel[c];
    if (material.kd[c] < 0) problems.push_back(std::string(info.kd) + " is negative in " + ch);
    if (!info.ks.empty() && material.ks[c] < 0)
      problems.push_back(std::string(info.ks) + " is negative in " + ch);
    switch (material.model) {
      case Model::kLambert:
        if (material.kd[c] > 1) problems.push_back("rho exceeds 1 in " + ch);
        break;
      case Model::kLafortune:
      case Model::kBlinnPhong:
      case Model::kWard:
        if (material.kd[c] + material.ks[c] > 1)
          problems.push_back(std::string(info.kd) + " + " + std::string(info.ks) +
                             " exceeds 1 in " + ch);
        break;
      case Model::kGgx:
        if (material.ks[c] > 1) problems.push_back("f0 exceeds 1 in " + ch);
        if (material.kd[c] + material.ks[c] > 1) problems.push_back("kd + f0 exceeds 1 in " + ch);
        break;
    }
    if (!info.shape.empty() && !(material.shape[c] > 0))
      problems.push_back(std::string(info.shape) + " is not positive in " + ch);
  }
  return problems;
}

}  // namespace brdf
