#include "brdf/core/models.h"
#include "brdf/core/text_format.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "brdf/core/error.h"
#include "brdf/core/json_error.h"

namespace brdf {
namespace {

// Ranges: reflectances and engine UI sliders in [0, 1]; lobe exponents n in [0.001, 10⁶] (beyond
// 10⁶ the lobe is narrower than any instrument resolves and pow() loses all precision); widths
// α in [0.001, 1] (α > 1 is rougher than a uniform distribution of slopes: no real surface).
ParameterInfo Rgb01(std::string_view name, double start, std::string_view label = {}) {
  return {name, true, 0.0, 1.0, start, false, label, 0};
}
ParameterInfo Scalar01(std::string_view name, double start, std::string_view label = {}) {
  return {name, false, 0.0, 1.0, start, false, label, 0};
}
ParameterInfo Exponent(std::string_view name) { return {name, true, 1e-3, 1e6, 20.0, true, {}, 0}; }
ParameterInfo Width(std::string_view name) { return {name, true, 1e-3, 1.0, 0.2, true, {}, 0}; }

ModelInfo Info(Model model, std::string_view name, std::string_view engine,
               std::vector<ParameterInfo> parameters, int shape) {
  ModelInfo info{model, name, engine, std::move(parameters), 0, shape};
  for (ParameterInfo& p : info.parameters) {
    p.offset = info.value_count;
    info.value_count += p.Count();
  }
  return info;
}

const std::vector<ModelInfo>& Registry() {
  static const std::vector<ModelInfo> registry = {
      Info(Model::kLambert, "lambert", "", {Rgb01("rho", 0.5)}, -1),
      Info(Model::kLafortune, "lafortune", "", {Rgb01("kd", 0.3), Rgb01("ks", 0.3), Exponent("n")},
           2),
      Info(Model::kBlinnPhong, "blinn-phong", "",
           {Rgb01("kd", 0.3), Rgb01("ks", 0.3), Exponent("n")}, 2),
      Info(Model::kGgx, "ggx", "", {Rgb01("kd", 0.3), Rgb01("f0", 0.3), Width("alpha")}, 2),
      Info(Model::kWard, "ward", "", {Rgb01("rho_d", 0.3), Rgb01("rho_s", 0.3), Width("alpha")}, 2),
      Info(Model::kUnrealDefaultLit, "unreal-defaultlit", "Unreal Engine",
           {Rgb01("base_color", 0.5, "Base Color"), Scalar01("metallic", 0.5, "Metallic"),
            Scalar01("specular", 0.5, "Specular"), Scalar01("roughness", 0.5, "Roughness")},
           3),
      Info(Model::kUnityHdrpLit, "unity-hdrp-lit", "Unity HDRP",
           {Rgb01("base_color", 0.5, "Base Map"), Scalar01("metallic", 0.5, "Metallic"),
            Scalar01("smoothness", 0.5, "Smoothness")},
           2),
      Info(Model::kUnityHdrpLitSpecular, "unity-hdrp-lit-specular", "Unity HDRP",
           {Rgb01("base_color", 0.5, "Base Map"), Rgb01("specular_color", 0.3, "Specular Color"),
            Scalar01("smoothness", 0.5, "Smoothness")},
           2),
      Info(Model::kUnityUrpLit, "unity-urp-lit", "Unity URP",
           {Rgb01("base_color", 0.5, "Base Map"), Scalar01("metallic", 0.5, "Metallic"),
            Scalar01("smoothness", 0.5, "Smoothness")},
           2),
      Info(Model::kUnityUrpLitSpecular, "unity-urp-lit-specular", "Unity URP",
           {Rgb01("base_color", 0.5, "Base Map"), Rgb01("specular_color", 0.3, "Specular Map"),
            Scalar01("smoothness", 0.5, "Smoothness")},
           2),
  };
  return registry;
}

constexpr Model kAllModels[] = {
    Model::kLambert,      Model::kLafortune,
    Model::kBlinnPhong,   Model::kGgx,
    Model::kWard,         Model::kUnrealDefaultLit,
    Model::kUnityHdrpLit, Model::kUnityHdrpLitSpecular,
    Model::kUnityUrpLit,  Model::kUnityUrpLitSpecular,
};

std::string KnownModelNames() {
  std::string names;
  for (const auto& info : Registry()) {
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

std::string RangeText(const ParameterInfo& p) {
  return "a finite number in [" + ShortNumberText(p.min) + ", " + ShortNumberText(p.max) + "]";
}

// Reads one parameter into `out` (Count() values), checking finiteness and range.
void ReadParameter(const nlohmann::json& object, const ParameterInfo& p, const std::string& file,
                   double* out) {
  const std::string member(p.name);
  const auto it = object.find(member);
  const std::string shape = p.rgb ? "a number or an [r, g, b] array" : "a number";
  if (it == object.end())
    throw FormatError(file, "member '" + member + "'", shape, "nothing (the member is missing)");
  auto read_number = [&](const nlohmann::json& v, const std::string& where) {
    if (!v.is_number()) throw FormatError(file, where, RangeText(p), Abbreviate(v));
    const double d = v.get<double>();
    if (!std::isfinite(d) || d < p.min || d > p.max)
      throw FormatError(file, where, RangeText(p), Abbreviate(v));
    return d;
  };
  if (it->is_number()) {
    const double d = read_number(*it, "member '" + member + "'");
    for (int c = 0; c < p.Count(); ++c) out[c] = d;
  } else if (p.rgb && it->is_array() && it->size() == 3) {
    for (int c = 0; c < 3; ++c)
      out[c] = read_number((*it)[c], "member '" + member + "'[" + std::to_string(c) + "]");
  } else {
    throw FormatError(file, "member '" + member + "'", shape, Abbreviate(*it));
  }
}

nlohmann::json ParameterJson(const Material& m, const ParameterInfo& p) {
  const double* v = m.values.data() + p.offset;
  if (!p.rgb || (v[0] == v[1] && v[1] == v[2])) return v[0];
  return nlohmann::json::array({v[0], v[1], v[2]});
}

}  // namespace

const ModelInfo& DescribeModel(Model model) {
  for (const auto& info : Registry())
    if (info.model == model) return info;
  return Registry().front();
}

std::span<const Model> AllModels() { return kAllModels; }

std::string_view ModelName(Model model) { return DescribeModel(model).name; }

Model ModelFromName(std::string_view name) {
  for (const auto& info : Registry())
    if (info.name == name) return info.model;
  throw InvalidArgument("unknown BRDF model '" + std::string(name) +
                        "' (known: " + KnownModelNames() + ")");
}

Material Material::Make(Model model, const std::vector<Rgb>& parameters,
                        std::string material_name) {
  const ModelInfo& info = DescribeModel(model);
  if (parameters.size() != info.parameters.size())
    throw InvalidArgument("model " + std::string(info.name) + " has " +
                          std::to_string(info.parameters.size()) + " parameters, got " +
                          std::to_string(parameters.size()));
  Material m;
  m.model = model;
  m.name = std::move(material_name);
  for (std::size_t i = 0; i < parameters.size(); ++i)
    m.SetParameter(static_cast<int>(i), parameters[i]);
  return m;
}

Rgb Material::Parameter(int index) const {
  const ParameterInfo& p = DescribeModel(model).parameters.at(static_cast<std::size_t>(index));
  const double* v = values.data() + p.offset;
  return p.rgb ? Rgb{v[0], v[1], v[2]} : Rgb{v[0], v[0], v[0]};
}

Rgb Material::Parameter(std::string_view parameter_name) const {
  const ModelInfo& info = DescribeModel(model);
  for (std::size_t i = 0; i < info.parameters.size(); ++i)
    if (info.parameters[i].name == parameter_name) return Parameter(static_cast<int>(i));
  throw InvalidArgument("model " + std::string(info.name) + " has no parameter '" +
                        std::string(parameter_name) + "'");
}

void Material::SetParameter(int index, const Rgb& value) {
  const ParameterInfo& p = DescribeModel(model).parameters.at(static_cast<std::size_t>(index));
  for (int c = 0; c < p.Count(); ++c) values[static_cast<std::size_t>(p.offset + c)] = value[c];
}

Material ParseMaterialJson(std::string_view json_text, const std::string& file) {
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(json_text.begin(), json_text.end());
  } catch (const nlohmann::json::parse_error& e) {
    throw JsonSyntaxError(file, json_text, e.byte);
  } catch (const nlohmann::json::out_of_range&) {
    // A number literal beyond double's range (1e400), i.e. an infinity.
    throw JsonNumberTooLargeError(file, json_text);
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
  const ModelInfo& info = DescribeModel(m.model);
  for (const ParameterInfo& p : info.parameters)
    ReadParameter(doc, p, file, m.values.data() + p.offset);

  nlohmann::json extra = nlohmann::json::object();
  for (auto it = doc.begin(); it != doc.end(); ++it) {
    const std::string& key = it.key();
    bool is_parameter = key == "model";
    for (const ParameterInfo& p : info.parameters) is_parameter |= key == p.name;
    if (is_parameter) continue;
    if (key == "name" || key == "description") {
      if (!it->is_string())
        throw FormatError(file, "member '" + key + "'", "a string", Abbreviate(*it));
      (key == "name" ? m.name : m.description) = it->get<std::string>();
      continue;
    }
    extra[key] = *it;
  }
  m.extra_json = extra.dump();
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
  const ModelInfo& info = DescribeModel(material.model);
  nlohmann::ordered_json doc;
  if (!material.name.empty()) doc["name"] = material.name;
  if (!material.description.empty()) doc["description"] = material.description;
  doc["model"] = info.name;
  for (const ParameterInfo& p : info.parameters)
    doc[std::string(p.name)] = ParameterJson(material, p);
  const auto extra = nlohmann::json::parse(material.extra_json, nullptr, false);
  if (extra.is_object())
    for (auto it = extra.begin(); it != extra.end(); ++it) doc[it.key()] = *it;
  return doc.dump(2) + "\n";
}

std::vector<std::string> PhysicalProblems(const Material& material) {
  std::vector<std::string> problems;
  const ModelInfo& info = DescribeModel(material.model);
  static const char* kChannel[] = {"red", "green", "blue"};
  for (const ParameterInfo& p : info.parameters) {
    for (int c = 0; c < p.Count(); ++c) {
      const double v = material.values[static_cast<std::size_t>(p.offset + c)];
      const std::string where =
          std::string(p.name) + (p.rgb ? std::string(" in ") + kChannel[c] : std::string());
      if (!std::isfinite(v))
        problems.push_back(where + " is not a finite number");
      else if (v < p.min)
        problems.push_back(where +
                           (p.min == 0 ? " is negative" : " is below " + ShortNumberText(p.min)));
      else if (v > p.max)
        problems.push_back(where + " exceeds " + ShortNumberText(p.max));
    }
  }
  // Energy: the diffuse and specular reflectances of the legacy models share one budget.
  if (material.model == Model::kLafortune || material.model == Model::kBlinnPhong ||
      material.model == Model::kWard || material.model == Model::kGgx) {
    const ParameterInfo& d = info.parameters[0];
    const ParameterInfo& s = info.parameters[1];
    for (int c = 0; c < 3; ++c)
      if (material.values[static_cast<std::size_t>(d.offset + c)] +
              material.values[static_cast<std::size_t>(s.offset + c)] >
          1)
        problems.push_back(std::string(d.name) + " + " + std::string(s.name) + " exceeds 1 in " +
                           kChannel[c]);
  }
  return problems;
}

std::string EngineInstructions(const Material& material) {
  const ModelInfo& info = DescribeModel(material.model);
  if (info.engine.empty()) return {};
  std::string out;
  for (const ParameterInfo& p : info.parameters) {
    if (!out.empty()) out += ", ";
    out += std::string(p.engine_label);
    char buf[64];
    for (int c = 0; c < p.Count(); ++c) {
      std::snprintf(buf, sizeof buf, " %.2f",
                    material.values[static_cast<std::size_t>(p.offset + c)]);
      out += buf;
    }
  }
  return out;
}

}  // namespace brdf
