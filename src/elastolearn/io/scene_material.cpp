#include <elastolearn/core/error.hpp>
#include <elastolearn/io/scene_material.hpp>
#include <elastolearn/material/elastic_model_type.hpp>
#include <elastolearn/material/rayleigh_damping.hpp>
#include <elastolearn/material/spline_edited.hpp>
#include <elastolearn/material/stretch_dependent_rayleigh.hpp>

namespace elastolearn::io {

namespace {

material::CubicSpline parse_spline(
    const JsonObject& o, const std::string& x_key, const std::string& y_key) {
  auto x = o.numbers(x_key);
  auto y = o.numbers(y_key);
  if (x.size() != y.size())
    o.fail(y_key, "needs as many values as '" + x_key + "' (" + std::to_string(x.size()) + ")");
  return material::CubicSpline(std::move(x), std::move(y), o.file() + ": " + o.field(x_key));
}

/// The damping law of a "damping" object (its coefficients; the tangent is set by the caller).
std::shared_ptr<material::DampingModel> make_damping(const JsonObject& d) {
  const bool stretch_dependent = (d.has("alpha0") && d.json().at("alpha0").is_object())
      || (d.has("alpha1") && d.json().at("alpha1").is_object());
  if (!stretch_dependent)
    return std::make_shared<material::RayleighDamping>(
        d.number("alpha0", 0.0), d.number("alpha1", 0.0), d.file() + ": " + d.path());
  // A coefficient is a number, a spline {"stretches", "values"} or a polynomial in σ₁ − 1
  // {"polynomial": [c₀, c₁, ...]}.
  auto curve = [&](const std::string& key) -> material::StretchCurve {
    if (!d.has(key))
      return material::StretchCurve::constant(0.0);
    if (!d.json().at(key).is_object())
      return material::StretchCurve::constant(d.number(key));
    const JsonObject s = d.object(key);
    s.reject_unknown_keys({ "stretches", "values", "polynomial" });
    if (!s.has("polynomial"))
      return parse_spline(s, "stretches", "values");
    if (s.has("stretches") || s.has("values"))
      s.fail("polynomial",
          "give either a polynomial or a spline's \"stretches\" and \"values\", not both");
    return material::StretchPolynomial(
        s.numbers("polynomial"), s.file() + ": " + s.field("polynomial"));
  };
  return std::make_shared<material::StretchDependentRayleigh>(
      curve("alpha0"), curve("alpha1"), d.file() + ": " + d.path());
}

/// The "damping" object: coefficients and the stiffness α₁ scales ("tangent").
std::shared_ptr<const material::DampingModel> parse_damping(const JsonObject& d) {
  d.reject_unknown_keys({ "alpha0", "alpha1", "tangent" });
  const auto tangent = material::damping_tangent_from_string(
      d.choice("tangent", { "flip-free", "exact" }, "flip-free"),
      d.file() + ": " + d.field("tangent"));
  std::shared_ptr<material::DampingModel> model = make_damping(d);
  model->set_tangent(tangent);
  return model;
}

} // namespace

fem::MaterialModel parse_material(const JsonObject& o) {
  o.reject_unknown_keys({ "model", "young", "poisson", "density", "edit", "damping" });
  fem::MaterialModel model;
  const auto type = material::elastic_model_type_from_string(
      o.choice("model", { "corotated", "stvk", "neohookean", "spline_edited" }),
      o.file() + ": " + o.field("model"));
  const double young = o.positive("young");
  const double poisson = o.number("poisson");
  if (!(poisson > -1 && poisson < 0.5))
    o.fail("poisson", "must be in (-1, 0.5), got " + std::to_string(poisson));
  const auto lame = material::Lame::from_young_poisson(young, poisson);
  model.density = o.positive("density", 1000.0);
  if (type == material::ElasticModelType::SplineEdited) {
    const JsonObject edit = o.object("edit");
    edit.reject_unknown_keys({ "base", "region", "stretches", "scales" });
    const auto base = material::elastic_model_type_from_string(
        edit.choice("base", { "neohookean", "corotated" }, "neohookean"),
        edit.file() + ": " + edit.field("base"));
    const auto region = material::spline_edit_region_from_string(
        edit.choice("region", { "tension", "compression" }),
        edit.file() + ": " + edit.field("region"));
    model.elastic = std::make_shared<material::SplineEditedModel>(base, lame, region,
        parse_spline(edit, "stretches", "scales"), edit.file() + ": " + edit.path());
  } else {
    if (o.has("edit"))
      o.fail("edit", "only allowed with \"model\": \"spline_edited\"");
    model.elastic = material::make_elastic_model(type, lame);
  }
  if (o.has("damping"))
    model.damping = parse_damping(o.object("damping"));
  return model;
}

} // namespace elastolearn::io
