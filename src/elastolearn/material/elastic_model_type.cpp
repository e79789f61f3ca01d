#include <elastolearn/core/error.hpp>
#include <elastolearn/material/corotated.hpp>
#include <elastolearn/material/elastic_model_type.hpp>
#include <elastolearn/material/neohookean.hpp>
#include <elastolearn/material/stvk.hpp>

namespace elastolearn::material {

std::string to_string(ElasticModelType type) {
  switch (type) {
  case ElasticModelType::Corotated:
    return "corotated";
  case ElasticModelType::StVK:
    return "stvk";
  case ElasticModelType::NeoHookean:
    return "neohookean";
  case ElasticModelType::SplineEdited:
    return "spline_edited";
  }
  ELASTOLEARN_CHECK(false, "unknown ElasticModelType " + std::to_string(static_cast<int>(type)));
  return {};
}

ElasticModelType elastic_model_type_from_string(std::string_view name, const std::string& where) {
  std::string valid;
  for (ElasticModelType t : all_elastic_model_types) {
    const std::string s = to_string(t);
    if (s == name)
      return t;
    valid += (valid.empty() ? "" : ", ") + s;
  }
  throw InputError(
      where, "unknown elastic model '" + std::string(name) + "' (valid: " + valid + ")");
}

std::unique_ptr<ElasticModel> make_elastic_model(ElasticModelType type, const Lame& lame) {
  switch (type) {
  case ElasticModelType::Corotated:
    return std::make_unique<CorotatedModel>(lame);
  case ElasticModelType::StVK:
    return std::make_unique<StVKModel>(lame);
  case ElasticModelType::NeoHookean:
    return std::make_unique<NeoHookeanModel>(lame);
  case ElasticModelType::SplineEdited:
    throw InputError("elastic model",
        "'spline_edited' needs a base model, a region and a spline; build a "
        "SplineEditedModel instead of calling make_elastic_model");
  }
  ELASTOLEARN_CHECK(false, "unknown ElasticModelType " + std::to_string(static_cast<int>(type)));
  return {};
}

} // namespace elastolearn::material
