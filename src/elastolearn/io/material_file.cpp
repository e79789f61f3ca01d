#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/io/material_file.hpp>
#include <elastolearn/io/scene_material.hpp>
#include <elastolearn/material/nn_correction.hpp>
#include <elastolearn/material/rbf_correction.hpp>

#include <algorithm>
#include <cmath>
#include <optional>

namespace elastolearn::io {

using Json = nlohmann::json;

namespace {

constexpr const char* k_format_kind = "elastolearn-material";
constexpr int k_format_version = 1;

// ---- writing ---------------------------------------------------------------------------------

/// A matrix as an array of rows (row i = [M(i,0), M(i,1), ...]).
template <typename Derived> Json rows_to_json(const Eigen::MatrixBase<Derived>& m) {
  Json out = Json::array();
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    Json row = Json::array();
    for (Eigen::Index j = 0; j < m.cols(); ++j)
      row.push_back(double(m(i, j)));
    out.push_back(std::move(row));
  }
  return out;
}

template <typename Derived> Json vector_to_json(const Eigen::MatrixBase<Derived>& v) {
  Json out = Json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i)
    out.push_back(double(v[i]));
  return out;
}

/// [min, max], null for an unbounded end (JSON has no infinity).
Json trusted_to_json(const material::TrustedStretches& t) {
  return Json::array({ std::isfinite(t.min) ? Json(t.min) : Json(nullptr),
      std::isfinite(t.max) ? Json(t.max) : Json(nullptr) });
}

/// "continuation" (and its bound) next to "trusted_stretches" in `out`.
void continuation_to_json(const material::TrustedStretches& t, Json& out) {
  out["trusted_stretches"] = trusted_to_json(t);
  out["continuation"] = material::continuation_name(t.continuation);
  if (t.continuation != material::Continuation::edge_hessian) {
    out["nominal_stiffness"] = rows_to_json(t.nominal_stiffness);
    out["kept_stiffness"] = t.kept_stiffness;
  }
  if (t.smooth())
    out["clamp_width"] = t.clamp_width;
}

Json rbf_to_json(const material::RbfCorrection& c) {
  const auto& p = c.parameters();
  // JSON has no infinity: "no floor" (−∞) is written as null.
  const Json floor = std::isfinite(p.damping_floor) ? Json(p.damping_floor) : Json(nullptr);
  Json out { { "type", "rbf" }, { "energy_kernels", p.energy_kernels }, { "epsilon", p.epsilon },
    { "centres", rows_to_json(p.centres) }, { "weights", vector_to_json(p.weights) },
    { "own_slope", p.own_slope }, { "other_slope", p.other_slope }, { "constant", p.constant },
    { "quadratic", vector_to_json(p.quadratic) }, { "neo_hookean", vector_to_json(p.neo_hookean) },
    { "damping_weights", vector_to_json(p.damping_weights) },
    { "damping_slopes", vector_to_json(p.damping_slopes) },
    { "damping_constant", p.damping_constant },
    { "damping_quadratic", vector_to_json(p.damping_quadratic) }, { "damping_floor", floor } };
  if (p.mass_damping != 0) // written only when learned, so other files keep their exact form
    out["mass_damping"] = p.mass_damping;
  continuation_to_json(p.trusted, out);
  return out;
}

Json nn_to_json(const material::NnCorrection& c) {
  const auto& p = c.parameters();
  Json layers = Json::array();
  for (const auto& layer : p.layers)
    layers.push_back(
        Json { { "weight", rows_to_json(layer.weight) }, { "bias", vector_to_json(layer.bias) } });
  Json out { { "type", "nn" }, { "kind", material::to_string(p.kind) },
    { "activation", material::to_string(p.activation) },
    { "input_mean", vector_to_json(p.input_mean) },
    { "input_scale", vector_to_json(p.input_scale) }, { "output_mean", p.output_mean },
    { "output_scale", p.output_scale }, { "layers", std::move(layers) } };
  if (p.kind == material::NnKind::Energy) {
    out["polynomial"] = vector_to_json(p.polynomial);
    continuation_to_json(p.trusted, out);
  }
  if (p.damping)
    out["damping"] = rbf_to_json(*p.damping);
  return out;
}

// ---- reading ---------------------------------------------------------------------------------

/// Array of finite numbers of length `size` (any length if size < 0).
VecX read_vector(const JsonObject& o, const std::string& key, Eigen::Index size = -1) {
  const std::vector<double> v = o.numbers(key);
  if (size >= 0 && Eigen::Index(v.size()) != size) {
    o.fail(key, "expected " + std::to_string(size) + " numbers, got " + std::to_string(v.size()));
  }
  return Eigen::Map<const VecX>(v.data(), Eigen::Index(v.size()));
}

/// Array of rows, each an array of finite numbers; `rows`/`cols` < 0 accept any count (but all
/// rows must have the same length). An empty array is a 0 × max(cols, 0) matrix.
MatX read_rows(const JsonObject& o, const std::string& key, Eigen::Index rows, Eigen::Index cols) {
  if (!o.has(key))
    o.fail(key, "missing required field");
  const Json& v = o.json().at(key);
  if (!v.is_array())
    o.fail(key, "expected an array of rows, got " + describe_json(v));
  if (rows >= 0 && Eigen::Index(v.size()) != rows) {
    o.fail(key, "expected " + std::to_string(rows) + " rows, got " + std::to_string(v.size()));
  }
  const Eigen::Index n = Eigen::Index(v.size());
  Eigen::Index width = cols;
  if (width < 0)
    width = n > 0 && v[0].is_array() ? Eigen::Index(v[0].size()) : 0;
  MatX m(n, width);
  for (Eigen::Index i = 0; i < n; ++i) {
    const std::string row_key = key + "[" + std::to_string(i) + "]";
    const Json& row = v[std::size_t(i)];
    if (!row.is_array() || Eigen::Index(row.size()) != width) {
      o.fail(row_key,
          "expected an array of " + std::to_string(width) + " numbers, got " + describe_json(row));
    }
    for (Eigen::Index j = 0; j < width; ++j) {
      const Json& e = row[std::size_t(j)];
      if (!e.is_number() || !std::isfinite(e.get<double>())) {
        o.fail(row_key + "[" + std::to_string(j) + "]",
            "expected a finite number, got " + describe_json(e));
      }
      m(i, j) = e.get<double>();
    }
  }
  return m;
}

/// A correction's "trusted_stretches" and how it is continued beyond them ("continuation", with
/// "nominal_stiffness" and "kept_stiffness" for all but edge_hessian, "clamp_width" for
/// smooth_clamp and smooth_expansion); absent (older files):
/// unbounded, and continued with the edge's Hessian as those files were.
material::TrustedStretches trusted_from_json(const JsonObject& o) {
  material::TrustedStretches t;
  t.continuation = material::continuation_from_name(
      o.choice("continuation", material::continuation_names(), "edge_hessian"), "continuation");
  if (t.continuation != material::Continuation::edge_hessian) {
    t.nominal_stiffness = read_rows(o, "nominal_stiffness", 3, 3);
    t.kept_stiffness = o.number("kept_stiffness");
  }
  if (t.smooth())
    t.clamp_width = o.number("clamp_width");
  if (!o.has("trusted_stretches"))
    return t;
  const Json& j = o.json().at("trusted_stretches");
  if (!j.is_array() || j.size() != 2 || !std::all_of(j.begin(), j.end(), [](const Json& v) {
        return v.is_null() || v.is_number();
      }))
    o.fail("trusted_stretches", "expected [min, max] (numbers, or null for an unbounded end)");
  if (!j[0].is_null())
    t.min = j[0].get<double>();
  if (!j[1].is_null())
    t.max = j[1].get<double>();
  return t;
}

/// Run a correction constructor; its InputError("rbf_correction.weights", ...) is re-thrown
/// naming the file and the JSON field ("learned.json: correction.weights").
template <typename Make> auto construct(const JsonObject& o, Make&& make) {
  try {
    return make();
  } catch (const InputError& e) {
    const std::string& where = e.where();
    const std::size_t dot = where.find('.');
    const std::string field = dot == std::string::npos ? std::string() : where.substr(dot + 1);
    const std::string what = e.what();
    o.fail(field, where.empty() ? what : what.substr(std::min(what.size(), where.size() + 2)));
  }
}

std::shared_ptr<const material::RbfCorrection> rbf_from_json(const JsonObject& o) {
  o.reject_unknown_keys({ "type", "energy_kernels", "epsilon", "centres", "weights", "own_slope",
      "other_slope", "constant", "quadratic", "neo_hookean", "damping_weights", "damping_slopes",
      "damping_slope", "damping_constant", "damping_quadratic", "damping_floor", "mass_damping",
      "trusted_stretches", "continuation", "nominal_stiffness", "kept_stiffness", "clamp_width" });
  material::RbfCorrection::Parameters p;
  p.energy_kernels = o.boolean("energy_kernels", false); // absent: the stress kernels
  p.epsilon = o.number("epsilon");
  p.centres = read_rows(o, "centres", -1, 3);
  p.weights = read_vector(o, "weights", p.centres.rows());
  p.own_slope = o.number("own_slope", 0.0);
  p.other_slope = o.number("other_slope", 0.0);
  p.constant = o.number("constant", 0.0);
  if (o.has("quadratic"))
    p.quadratic = read_vector(o, "quadratic", 4);
  if (o.has("neo_hookean"))
    p.neo_hookean = read_vector(o, "neo_hookean", 2);
  if (o.has("damping_weights")) {
    p.damping_weights = read_vector(o, "damping_weights");
    if (p.damping_weights.size() != 0 && p.damping_weights.size() != p.centres.rows()) {
      o.fail("damping_weights",
          "expected none or one per centre (" + std::to_string(p.centres.rows()) + "), got "
              + std::to_string(p.damping_weights.size()));
    }
  }
  if (o.has("damping_slopes") && o.has("damping_slope"))
    o.fail("damping_slope",
        "give either damping_slopes or the older damping_slope (a slope along Σσ − 3), not both");
  if (o.has("damping_slopes"))
    p.damping_slopes = read_vector(o, "damping_slopes", 3);
  else // older files: one slope along the trace Σσ − 3 = Σ (s_k − 1), i.e. equal sorted slopes
    p.damping_slopes.setConstant(o.number("damping_slope", 0.0));
  p.damping_constant = o.number("damping_constant", 0.0);
  if (o.has("damping_quadratic"))
    p.damping_quadratic = read_vector(o, "damping_quadratic", 3);
  if (o.has("damping_floor") && !o.json().at("damping_floor").is_null())
    p.damping_floor = o.number("damping_floor");
  p.mass_damping = o.number("mass_damping", 0.0);
  p.trusted = trusted_from_json(o);
  return construct(
      o, [&] { return std::make_shared<const material::RbfCorrection>(std::move(p)); });
}

std::shared_ptr<const material::Correction> nn_from_json(const JsonObject& o) {
  o.reject_unknown_keys({ "type", "kind", "activation", "input_mean", "input_scale", "output_mean",
      "output_scale", "polynomial", "layers", "damping", "trusted_stretches", "continuation",
      "nominal_stiffness", "kept_stiffness", "clamp_width" });
  material::NnCorrection::Parameters p;
  // Absent: the stress network with ELU (files written before the energy network).
  p.kind = o.has("kind") && o.choice("kind", { "stress", "energy" }) == "energy"
      ? material::NnKind::Energy
      : material::NnKind::Stress;
  if (o.has("activation"))
    p.activation = *material::activation_from_string(
        o.choice("activation", { "elu", "relu", "sigmoid", "softplus", "tanh", "squareplus" }));
  const Eigen::Index inputs = p.kind == material::NnKind::Energy ? 3 : 6;
  p.input_mean = read_vector(o, "input_mean", inputs);
  p.input_scale = read_vector(o, "input_scale", inputs);
  if (p.kind == material::NnKind::Energy)
    p.polynomial = read_vector(o, "polynomial", 6);
  else if (o.has("polynomial"))
    o.fail("polynomial", "is only for \"kind\": \"energy\"");
  p.trusted = trusted_from_json(o); // a stress network refuses a bounded one
  // Scalars: one network g shared by the three principal directions (NnCorrection).
  p.output_mean = o.number("output_mean");
  p.output_scale = o.number("output_scale");
  const auto layers = o.objects("layers");
  if (layers.empty())
    o.fail("layers", "expected at least one layer");
  Eigen::Index in = inputs;
  for (const JsonObject& l : layers) {
    l.reject_unknown_keys({ "weight", "bias" });
    material::NnCorrection::Layer layer;
    layer.weight = read_rows(l, "weight", -1, in);
    layer.bias = read_vector(l, "bias", layer.weight.rows());
    in = layer.weight.rows();
    p.layers.push_back(std::move(layer));
  }
  if (o.has("damping")) {
    // The stiffness-damping correction Δα₁, an RBF with no elastic part (NnCorrection::damping).
    const JsonObject d = o.object("damping");
    d.choice("type", { "rbf" });
    p.damping = rbf_from_json(d);
  }
  return construct(o, [&] { return std::make_shared<const material::NnCorrection>(std::move(p)); });
}

} // namespace

Json correction_to_json(const material::Correction& correction) {
  if (const auto* rbf = dynamic_cast<const material::RbfCorrection*>(&correction))
    return rbf_to_json(*rbf);
  if (const auto* nn = dynamic_cast<const material::NnCorrection*>(&correction))
    return nn_to_json(*nn);
  throw InputError("material file",
      "a correction of kind \"" + correction.name()
          + "\" cannot be saved (only \"rbf\" and \"nn\" can)");
}

std::shared_ptr<const material::Correction> correction_from_json(const JsonObject& object) {
  const std::string type = object.choice("type", { "rbf", "nn" });
  return type == "rbf" ? rbf_from_json(object) : nn_from_json(object);
}

Json stretch_range_to_json(const material::StretchRange& range) {
  return { { "min", vector_to_json(range.min) }, { "max", vector_to_json(range.max) } };
}

std::string describe_correction(const material::Correction& correction) {
  if (const auto* rbf = dynamic_cast<const material::RbfCorrection*>(&correction)) {
    std::string s = "rbf, " + std::to_string(rbf->num_centres()) + " centres";
    if (rbf->has_damping())
      s += ", with damping correction";
    return s;
  }
  if (const auto* nn = dynamic_cast<const material::NnCorrection*>(&correction)) {
    std::string s = "nn (" + material::to_string(nn->parameters().kind) + ", "
        + material::to_string(nn->parameters().activation) + "), "
        + std::to_string(nn->num_inputs());
    for (const auto& layer : nn->parameters().layers) {
      s += '-';
      s += std::to_string(layer.weight.rows());
    }
    if (nn->parameters().damping)
      s += ", with damping correction";
    return s;
  }
  return correction.name();
}

std::string describe_material_model(const fem::MaterialModel& model) {
  std::string s = model.elastic ? model.elastic->name() : std::string("(no elastic model)");
  if (model.stiffness_scale) {
    const auto [lo, hi]
        = std::minmax_element(model.stiffness_scale->begin(), model.stiffness_scale->end());
    s += ", heterogeneous (stiffness x" + to_text(*lo) + " to x" + to_text(*hi) + " by region)";
  }
  if (model.correction)
    s += " + correction (" + describe_correction(*model.correction) + ")";
  return s;
}

namespace {

/// {"min": [s₁, s₂, s₃], "max": [...]}: finite, min ≤ max per sorted stretch (s₃ may be
/// negative: an inverted element's smallest stretch is, material::principal_frame).
material::StretchRange stretch_range_from_json(const JsonObject& object) {
  object.reject_unknown_keys({ "min", "max" });
  material::StretchRange range;
  range.min = object.vec3("min");
  range.max = object.vec3("max");
  for (int k = 0; k < 3; ++k) {
    if (!(range.min[k] <= range.max[k]))
      object.fail("max",
          "entry " + std::to_string(k) + " (" + std::to_string(range.max[k]) + ") is below min's ("
              + std::to_string(range.min[k]) + ")");
  }
  return range;
}

} // namespace

MaterialFile parse_material_file(const Json& json, const std::string& file) {
  const JsonObject root(json, file);
  check_format(root, k_format_kind, k_format_version);
  root.reject_unknown_keys(
      { "format", "material", "correction", "training", "training_stretches" });
  MaterialFile out;
  out.material = root.object("material").json();
  (void)parse_material(root.object("material")); // validate now, naming this file
  if (root.has("correction") && !root.json().at("correction").is_null())
    out.correction = correction_from_json(root.object("correction"));
  if (root.has("training"))
    out.training = root.object("training").json();
  if (root.has("training_stretches") && !root.json().at("training_stretches").is_null())
    out.training_stretches = stretch_range_from_json(root.object("training_stretches"));
  return out;
}

MaterialFile read_material_file(const std::filesystem::path& path) {
  return parse_material_file(read_json_file(path), path.string());
}

Json material_file_to_json(const MaterialFile& file) {
  Json out = { { "format", std::string(k_format_kind) + "/" + std::to_string(k_format_version) },
    { "material", file.material } };
  out["correction"] = file.correction ? correction_to_json(*file.correction) : Json(nullptr);
  out["training"] = file.training;
  if (file.training_stretches)
    out["training_stretches"] = stretch_range_to_json(*file.training_stretches);
  return out;
}

void write_material_file(const std::filesystem::path& path, const MaterialFile& file) {
  const Json json = material_file_to_json(file);
  // What we write must read back: validate the whole document under the target's name.
  (void)parse_material_file(json, path.string());
  write_json_file(path, json);
}

fem::MaterialModel material_model(const MaterialFile& file, const std::string& source) {
  fem::MaterialModel model = parse_material(JsonObject(file.material, source, "material"));
  model.correction = file.correction;
  return model;
}

std::optional<std::filesystem::path> referenced_material(
    const JsonObject& scene, const std::filesystem::path& base_dir) {
  if (!scene.has("material") || !scene.json().at("material").is_string())
    return std::nullopt;
  std::filesystem::path p = scene.string("material");
  if (p.is_relative())
    p = base_dir / p;
  std::error_code ec;
  if (!std::filesystem::exists(p, ec))
    scene.fail("material", "material file " + p.string() + " does not exist");
  if (!std::filesystem::is_regular_file(p, ec))
    scene.fail("material", p.string() + " is not a material file (a folder?)");
  return p;
}

MaterialFile scene_material(const JsonObject& scene, const std::filesystem::path& base_dir) {
  if (const auto path = referenced_material(scene, base_dir))
    return read_material_file(*path);
  MaterialFile out;
  out.material = scene.object("material").json();
  return out;
}

fem::MaterialModel scene_material_model(
    const JsonObject& scene, const std::filesystem::path& base_dir, MaterialFile* file) {
  if (const auto path = referenced_material(scene, base_dir)) {
    MaterialFile read = read_material_file(*path);
    fem::MaterialModel model = material_model(read, path->string());
    if (file)
      *file = std::move(read);
    return model;
  }
  const JsonObject object = scene.object("material");
  fem::MaterialModel model = parse_material(object);
  if (file) {
    *file = MaterialFile();
    file->material = object.json();
  }
  return model;
}

} // namespace elastolearn::io
