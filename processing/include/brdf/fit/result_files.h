// The files a fit run writes, named in one place: each result is a material file (docs/design.md
// §9, with the FitReport under "fit") for one input and one model, and `brdf convert
// --engine-fits` finds the results of an input by the same names (engines::ReadFitResults).
//
// Where the results of a run go, given its output `out`:
//  - one input, one model (`single`): `out` itself, a .json file;
//  - one input, several models, `out` ending in .json: <out's stem>.<model>.json beside it;
//  - otherwise `out` is a folder receiving <input name>.<model>.json for every input and model.
// A tool asks Paths() before any fit and runs its overwrite check on exactly that list.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "brdf/core/models.h"

namespace brdf::processing {

// "<input name>.<model>.json", e.g. "gold.ggx.json".
inline std::string FitResultFileName(const std::string& input_name, Model model) {
  return input_name + "." + std::string(ModelName(model)) + ".json";
}

struct FitResultFiles {
  std::string out;         // a .json file or a folder, as above
  bool single = false;     // one input and one model: `out` is the result file
  bool one_input = false;  // one input: a .json `out` names the set of its results

  bool OutIsFile() const {
    std::string ext = std::filesystem::path(out).extension().string();
    for (char& c : ext)
      if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    return single || (one_input && ext == ".json");
  }
  // The result file of input `input_name` (its output name, the file stem) for `model`.
  std::string PathOf(const std::string& input_name, Model model) const {
    if (single) return out;
    const std::filesystem::path p(out);
    if (OutIsFile())
      return (p.parent_path() / FitResultFileName(p.stem().string(), model)).string();
    return (p / FitResultFileName(input_name, model)).string();
  }
  // Every result file, input by input and model by model in the given order.
  std::vector<std::string> Paths(const std::vector<std::string>& input_names,
                                 const std::vector<Model>& models) const {
    std::vector<std::string> paths;
    for (const std::string& name : input_names)
      for (Model m : models) paths.push_back(PathOf(name, m));
    return paths;
  }
  // The folder the results go into (to create before the fits; empty: the current folder).
  std::string Folder() const {
    return OutIsFile() ? std::filesystem::path(out).parent_path().string() : out;
  }
};

}  // namespace brdf::processing
