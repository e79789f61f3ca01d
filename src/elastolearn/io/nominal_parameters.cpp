#include <elastolearn/io/nominal_parameters.hpp>

namespace elastolearn::io {

learn::NominalParameters nominal_parameters_from_json(
    const JsonObject& material, material::ElasticModelType& type) {
  type = material::elastic_model_type_from_string(
      material.string("model"), material.file() + ": " + material.field("model"));
  learn::NominalParameters p;
  p.young = material.positive("young");
  p.poisson = material.number("poisson");
  if (material.has("damping")) {
    const JsonObject damping = material.object("damping");
    for (const char* key : { "alpha0", "alpha1" })
      if (damping.has(key) && !damping.json().at(key).is_number())
        damping.fail(key, "is stretch-dependent; a parameter fit moves constant coefficients");
    p.alpha0 = damping.number("alpha0", 0.0);
    p.alpha1 = damping.number("alpha1", 0.0);
  }
  return p;
}

nlohmann::json with_nominal_parameters(
    nlohmann::json material, const learn::NominalParameters& parameters, bool with_damping) {
  material["young"] = parameters.young;
  material["poisson"] = parameters.poisson;
  if (material.contains("damping") || with_damping) {
    nlohmann::json& damping = material["damping"];
    damping["alpha0"] = parameters.alpha0;
    damping["alpha1"] = parameters.alpha1;
  }
  return material;
}

nlohmann::json to_json(const learn::NominalParameters& p) {
  return { { "young", p.young }, { "poisson", p.poisson }, { "alpha0", p.alpha0 },
    { "alpha1", p.alpha1 } };
}

} // namespace elastolearn::io
