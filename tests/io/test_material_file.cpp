// Learned-material files: bit-exact round trips of RBF and NN corrections (parameters and the
// evaluated correction), the nominal material and provenance kept, scenes that reference a
// material file, and one InputError naming the file and field per kind of bad file.
#include "io_test_util.hpp"

#include <elastolearn/io/material_file.hpp>
#include <elastolearn/io/scene_file.hpp>
#include <elastolearn/material/analytic_correction.hpp>
#include <elastolearn/material/nn_correction.hpp>
#include <elastolearn/material/rbf_correction.hpp>

#include <gtest/gtest.h>

#include <fstream>
#include <limits>
#include <random>

using namespace elastolearn;
using namespace elastolearn::io;
using test::expect_input_error;
using test::ScratchDir;
namespace fs = std::filesystem;
using Json = nlohmann::json;

namespace {

/// Values that use every mantissa bit and span many magnitudes, so that any rounding in the
/// text representation would show as a mismatch in an exact comparison.
double awkward(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> e(-30, 30);
  return u(rng) * std::pow(10.0, e(rng)) / 3.0;
}

template <typename M> void fill(M& m, std::mt19937& rng) {
  for (Eigen::Index i = 0; i < m.size(); ++i)
    m.data()[i] = awkward(rng);
}

material::RbfCorrection::Parameters rbf_parameters(int centres, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> stretch(0.7, 1.3);
  material::RbfCorrection::Parameters p;
  p.centres.resize(centres, 3);
  for (Eigen::Index i = 0; i < p.centres.size(); ++i)
    p.centres.data()[i] = stretch(rng) + 1e-15 / 7;
  p.weights.resize(centres);
  fill(p.weights, rng);
  p.own_slope = awkward(rng);
  p.other_slope = awkward(rng);
  p.constant = awkward(rng);
  for (auto& q : p.quadratic)
    q = awkward(rng);
  for (auto& r : p.neo_hookean)
    r = awkward(rng);
  p.damping_weights.resize(centres);
  fill(p.damping_weights, rng);
  p.damping_slopes = Vec3(awkward(rng), awkward(rng), awkward(rng));
  p.damping_constant = awkward(rng);
  p.damping_quadratic = Vec3(awkward(rng), awkward(rng), awkward(rng));
  p.damping_floor = -0.002 / 3;
  p.epsilon = 1e-3 / 3;
  return p;
}

material::NnCorrection::Parameters nn_parameters(unsigned seed) {
  std::mt19937 rng(seed);
  material::NnCorrection::Parameters p;
  fill(p.input_mean, rng);
  p.input_scale = p.input_scale.array() + 1.0 / 3.0;
  p.output_mean = awkward(rng);
  p.output_scale = 2e5 / 7;
  std::normal_distribution<double> g(0.0, 0.5);
  const int widths[] = { 6, 6, 6, 1 };
  for (int k = 0; k + 1 < 4; ++k) {
    material::NnCorrection::Layer l;
    l.weight.resize(widths[k + 1], widths[k]);
    l.bias.resize(widths[k + 1]);
    for (Eigen::Index i = 0; i < l.weight.size(); ++i)
      l.weight.data()[i] = g(rng);
    for (Eigen::Index i = 0; i < l.bias.size(); ++i)
      l.bias[i] = g(rng);
    p.layers.push_back(std::move(l));
  }
  return p;
}

const Json k_nominal = Json::parse(R"({"model": "corotated", "young": 35000, "poisson": 0.43,
  "density": 1000, "damping": {"alpha0": 0.1, "alpha1": 0.002}})");

/// The correction and its gradient agree bit for bit at a spread of states.
void expect_same_function(const material::Correction& a, const material::Correction& b) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> s(0.6, 1.4), r(-2.0, 2.0);
  for (int i = 0; i < 50; ++i) {
    const Vec3 st(s(rng), s(rng), s(rng)), rate(r(rng), r(rng), r(rng));
    EXPECT_EQ(a.correction(st, rate), b.correction(st, rate));
    EXPECT_EQ(a.stiffness_damping(st), b.stiffness_damping(st));
    Mat3 ds_a, df_a, ds_b, df_b;
    a.correction_gradient(st, rate, ds_a, df_a);
    b.correction_gradient(st, rate, ds_b, df_b);
    EXPECT_EQ(ds_a, ds_b);
    EXPECT_EQ(df_a, df_b);
  }
}

/// A valid file with an RBF correction as JSON, for tests that break one field.
Json valid_rbf_file() {
  MaterialFile f;
  f.material = k_nominal;
  f.correction = std::make_shared<material::RbfCorrection>(rbf_parameters(4, 1));
  return material_file_to_json(f);
}

/// Parse `json` as "bad.json" and expect an InputError containing every one of `parts`.
void expect_bad(const Json& json, const std::vector<std::string>& parts) {
  expect_input_error([&] { parse_material_file(json, "bad.json"); }, parts);
}

} // namespace

TEST(MaterialFile, RbfRoundTripIsBitExact) {
  ScratchDir dir;
  MaterialFile f;
  f.material = k_nominal;
  const auto original = std::make_shared<material::RbfCorrection>(rbf_parameters(17, 5));
  f.correction = original;
  f.training = { { "iterations", 7 }, { "forward_error", 0.0123 } };
  write_material_file(dir / "learned.json", f);
  EXPECT_EQ(dir.files(), std::vector<std::string> { "learned.json" }); // no temporary left
  const MaterialFile g = read_material_file(dir / "learned.json");
  EXPECT_EQ(g.material, f.material);
  EXPECT_EQ(g.training, f.training);
  const auto* back = dynamic_cast<const material::RbfCorrection*>(g.correction.get());
  ASSERT_NE(back, nullptr);
  const auto& p = original->parameters();
  const auto& q = back->parameters();
  EXPECT_EQ(p.centres, q.centres);
  EXPECT_EQ(p.weights, q.weights);
  EXPECT_EQ(p.own_slope, q.own_slope);
  EXPECT_EQ(p.other_slope, q.other_slope);
  EXPECT_EQ(p.constant, q.constant);
  EXPECT_EQ(p.quadratic, q.quadratic);
  EXPECT_EQ(p.neo_hookean, q.neo_hookean);
  EXPECT_EQ(p.damping_weights, q.damping_weights);
  EXPECT_EQ(p.damping_slopes, q.damping_slopes);
  EXPECT_EQ(p.damping_floor, q.damping_floor);
  EXPECT_EQ(p.damping_constant, q.damping_constant);
  EXPECT_EQ(p.damping_quadratic, q.damping_quadratic);
  EXPECT_EQ(p.epsilon, q.epsilon);
  expect_same_function(*original, *back);
}

TEST(MaterialFile, MassDampingRoundTripsAndIsWrittenOnlyWhenLearned) {
  auto p = rbf_parameters(3, 8);
  MaterialFile f;
  f.material = k_nominal;
  f.correction = std::make_shared<material::RbfCorrection>(p);
  EXPECT_FALSE(material_file_to_json(f)["correction"].contains("mass_damping"))
      << "a file without Δα₀ keeps the form it had before the field";
  p.mass_damping = -0.1234567890123;
  f.correction = std::make_shared<material::RbfCorrection>(p);
  const Json j = material_file_to_json(f);
  const MaterialFile g = parse_material_file(Json::parse(j.dump()), "f.json");
  EXPECT_EQ(g.correction->mass_damping(), p.mass_damping);
  Json bad = j;
  bad["correction"]["mass_damping"] = "much";
  expect_bad(bad, { "bad.json: correction.mass_damping" });
}

TEST(MaterialFile, TrainingStretchesRoundTripAndAreOptional) {
  MaterialFile f = parse_material_file(valid_rbf_file(), "old.json");
  EXPECT_FALSE(f.training_stretches.has_value()) << "files before the field read without it";
  f.training_stretches.emplace();
  f.training_stretches->include(Vec3(1.0223, 1.0012, 0.9731));
  f.training_stretches->include(Vec3(1.0, 0.9876543210987654, 0.95));
  const Json j = material_file_to_json(f);
  const MaterialFile g = parse_material_file(Json::parse(j.dump()), "f.json");
  ASSERT_TRUE(g.training_stretches.has_value());
  EXPECT_EQ(g.training_stretches->min, f.training_stretches->min);
  EXPECT_EQ(g.training_stretches->max, f.training_stretches->max);

  Json bad = j;
  bad["training_stretches"]["max"][2] = 0.9; // below min's 0.95
  expect_bad(bad, { "bad.json: training_stretches.max", "entry 2" });
  bad = j;
  bad["training_stretches"]["min"][0] = nullptr; // what nlohmann writes for a NaN
  expect_bad(bad, { "bad.json: training_stretches.min", "3 finite numbers" });
  Json inverted = j; // an inverted element's smallest stretch is negative: valid
  inverted["training_stretches"]["min"][2] = -0.2;
  EXPECT_EQ(parse_material_file(inverted, "inv.json").training_stretches->min[2], -0.2);
  bad = j;
  bad["training_stretches"]["min"] = Json::array({ 1.0, 1.0 });
  expect_bad(bad, { "bad.json: training_stretches.min", "3 finite numbers" });
  bad = j;
  bad["training_stretches"]["mean"] = Json::array({ 1.0, 1.0, 1.0 });
  expect_bad(bad, { "bad.json: training_stretches", "mean" });
}

TEST(MaterialFile, RbfWithoutDampingFloorRoundTrips) {
  // The default floor is −∞ ("no floor"), which JSON cannot hold: it travels as null.
  auto p = rbf_parameters(3, 8);
  p.damping_floor = -std::numeric_limits<double>::infinity();
  MaterialFile f;
  f.material = k_nominal;
  f.correction = std::make_shared<material::RbfCorrection>(p);
  const Json j = material_file_to_json(f);
  EXPECT_TRUE(j["correction"]["damping_floor"].is_null());
  const MaterialFile g = parse_material_file(Json::parse(j.dump()), "f.json");
  const auto& q = dynamic_cast<const material::RbfCorrection&>(*g.correction).parameters();
  EXPECT_EQ(q.damping_floor, -std::numeric_limits<double>::infinity());
  expect_same_function(*f.correction, *g.correction);
}

TEST(MaterialFile, NnRoundTripIsBitExact) {
  ScratchDir dir;
  MaterialFile f;
  f.material = k_nominal;
  material::NnCorrection::Parameters parameters = nn_parameters(9);
  parameters.damping = std::make_shared<const material::RbfCorrection>(
      material::damping_part(material::RbfCorrection(rbf_parameters(4, 2))));
  const auto original = std::make_shared<material::NnCorrection>(parameters);
  ASSERT_NE(original->stiffness_damping(Vec3(1.1, 1, 0.9)), 0); // the damping travels too
  f.correction = original;
  write_material_file(dir / "nn.json", f);
  const MaterialFile g = read_material_file(dir / "nn.json");
  const auto* back = dynamic_cast<const material::NnCorrection*>(g.correction.get());
  ASSERT_NE(back, nullptr);
  const auto& p = original->parameters();
  const auto& q = back->parameters();
  EXPECT_EQ(p.input_mean, q.input_mean);
  EXPECT_EQ(p.input_scale, q.input_scale);
  EXPECT_EQ(p.output_mean, q.output_mean);
  EXPECT_EQ(p.output_scale, q.output_scale);
  ASSERT_EQ(p.layers.size(), q.layers.size());
  for (std::size_t k = 0; k < p.layers.size(); ++k) {
    EXPECT_EQ(p.layers[k].weight, q.layers[k].weight) << "layer " << k;
    EXPECT_EQ(p.layers[k].bias, q.layers[k].bias) << "layer " << k;
  }
  expect_same_function(*original, *back);
  EXPECT_EQ(describe_correction(*back), "nn (stress, elu), 6-6-6-1, with damping correction");
}

/// An energy network (NnKind::Energy) 3 → 8 → 8 → 1 with squareplus and a polynomial.
material::NnCorrection::Parameters energy_nn_parameters(unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 0.5);
  material::NnCorrection::Parameters p;
  p.kind = material::NnKind::Energy;
  p.activation = material::Activation::Squareplus;
  p.input_mean = Vec3(awkward(rng), awkward(rng), awkward(rng));
  p.input_scale = Vec3(0.1, 0.01, 0.001) / 3;
  p.output_scale = 2e3 / 7;
  for (Eigen::Index i = 0; i < 6; ++i)
    p.polynomial[i] = 1e4 * awkward(rng);
  const int widths[] = { 3, 8, 8, 1 };
  for (int k = 0; k + 1 < 4; ++k) {
    material::NnCorrection::Layer l;
    l.weight.resize(widths[k + 1], widths[k]);
    l.bias.resize(widths[k + 1]);
    for (Eigen::Index i = 0; i < l.weight.size(); ++i)
      l.weight.data()[i] = g(rng);
    for (Eigen::Index i = 0; i < l.bias.size(); ++i)
      l.bias[i] = g(rng);
    p.layers.push_back(std::move(l));
  }
  return p;
}

TEST(MaterialFile, EnergyNnRoundTripIsBitExact) {
  ScratchDir dir;
  MaterialFile f;
  f.material = k_nominal;
  material::NnCorrection::Parameters parameters = energy_nn_parameters(4);
  parameters.trusted = { 0.8 + 1e-15 / 3, 1.3 };
  parameters.damping = std::make_shared<const material::RbfCorrection>(
      material::damping_part(material::RbfCorrection(rbf_parameters(4, 2))));
  const auto original = std::make_shared<material::NnCorrection>(parameters);
  f.correction = original;
  write_material_file(dir / "energy.json", f);
  const MaterialFile g = read_material_file(dir / "energy.json");
  const auto* back = dynamic_cast<const material::NnCorrection*>(g.correction.get());
  ASSERT_NE(back, nullptr);
  const auto& q = back->parameters();
  EXPECT_EQ(q.kind, material::NnKind::Energy);
  EXPECT_EQ(q.activation, material::Activation::Squareplus);
  EXPECT_EQ(q.input_mean, parameters.input_mean);
  EXPECT_EQ(q.input_scale, parameters.input_scale);
  EXPECT_EQ(q.polynomial, parameters.polynomial);
  EXPECT_EQ(q.trusted.min, parameters.trusted.min);
  EXPECT_EQ(q.trusted.max, parameters.trusted.max);
  ASSERT_EQ(q.layers.size(), parameters.layers.size());
  for (std::size_t k = 0; k < q.layers.size(); ++k) {
    EXPECT_EQ(q.layers[k].weight, parameters.layers[k].weight) << "layer " << k;
    EXPECT_EQ(q.layers[k].bias, parameters.layers[k].bias) << "layer " << k;
  }
  expect_same_function(*original, *back);
  EXPECT_EQ(
      original->elastic_energy(Vec3(1.1, 0.9, 1.05)), back->elastic_energy(Vec3(1.1, 0.9, 1.05)));
  EXPECT_EQ(
      describe_correction(*back), "nn (energy, squareplus), 3-8-8-1, with damping correction");
}

TEST(MaterialFile, NetworkKindActivationAndPolynomialAreChecked) {
  MaterialFile nn;
  nn.material = k_nominal;
  nn.correction = std::make_shared<material::NnCorrection>(nn_parameters(1));
  // A file without kind and activation (written before the energy network) is the ELU stress
  // network.
  Json j = material_file_to_json(nn);
  j["correction"].erase("kind");
  j["correction"].erase("activation");
  const MaterialFile old = parse_material_file(j, "old.json");
  const auto& p = dynamic_cast<const material::NnCorrection&>(*old.correction).parameters();
  EXPECT_EQ(p.kind, material::NnKind::Stress);
  EXPECT_EQ(p.activation, material::Activation::Elu);
  j = material_file_to_json(nn);
  j["correction"]["activation"] = "gelu";
  expect_bad(j, { "bad.json: correction.activation", "\"squareplus\"" });
  j = material_file_to_json(nn);
  j["correction"]["polynomial"] = Json::array({ 0, 0, 0, 0, 0, 0 });
  expect_bad(j, { "bad.json: correction.polynomial", "energy" });
  j = material_file_to_json(nn);
  j["correction"]["kind"] = "energy"; // 6 input statistics for a 3-input network
  expect_bad(j, { "bad.json: correction.input_mean", "expected 3" });

  nn.correction = std::make_shared<material::NnCorrection>(energy_nn_parameters(2));
  j = material_file_to_json(nn);
  j["correction"].erase("polynomial");
  expect_bad(j, { "bad.json: correction.polynomial", "missing" });
  j = material_file_to_json(nn);
  j["correction"]["layers"][0]["weight"] = j["correction"]["layers"][1]["weight"];
  expect_bad(j, { "bad.json: correction.layers[0].weight" });
}

TEST(MaterialFile, NominalOnlyFileGivesTheSceneMaterialModel) {
  ScratchDir dir;
  MaterialFile f;
  f.material = k_nominal;
  write_material_file(dir / "nominal.json", f);
  const MaterialFile g = read_material_file(dir / "nominal.json");
  EXPECT_EQ(g.correction, nullptr);
  const fem::MaterialModel m = material_model(g, "nominal.json");
  EXPECT_EQ(m.elastic->name(), "corotated");
  EXPECT_EQ(m.correction, nullptr);
  ASSERT_NE(m.damping, nullptr);
  EXPECT_EQ(m.density, 1000.0);
  // With a correction, the model carries that very object.
  f.correction = std::make_shared<material::RbfCorrection>(rbf_parameters(3, 2));
  EXPECT_EQ(material_model(f, "x.json").correction, f.correction);
}

TEST(MaterialFile, UnsavableCorrectionKindIsRefusedAndNothingIsWritten) {
  ScratchDir dir;
  MaterialFile f;
  f.material = k_nominal;
  f.correction = std::make_shared<material::AnalyticCorrection>(
      material::AnalyticCorrection::Parameters { 1, 2, 3 });
  expect_input_error([&] { write_material_file(dir / "a.json", f); }, { "analytic" });
  f.correction = nullptr;
  f.material["young"] = -1;
  expect_input_error(
      [&] { write_material_file(dir / "b.json", f); }, { "b.json", "material.young" });
  EXPECT_TRUE(dir.files().empty());
}

TEST(MaterialFile, BadFilesNameTheFileAndField) {
  Json j = valid_rbf_file();
  EXPECT_NO_THROW(parse_material_file(j, "ok.json"));

  j["format"] = "elastolearn-scene/1";
  expect_bad(j, { "bad.json: format", "elastolearn-material/1" });

  j = valid_rbf_file();
  j["correction"].erase("weights");
  expect_bad(j, { "bad.json: correction.weights", "missing" });

  j = valid_rbf_file();
  j["correction"]["weights"].erase(1); // 3 weights for 4 centres
  expect_bad(j, { "bad.json: correction.weights", "expected 4 numbers" });

  j = valid_rbf_file();
  j["correction"]["centres"][2] = Json::array({ 1.0, 1.0 });
  expect_bad(j, { "bad.json: correction.centres[2]", "3 numbers" });

  j = valid_rbf_file();
  j["correction"]["damping_tangent"] = Json::array(); // a field of older development versions
  expect_bad(j, { "bad.json: correction", "damping_tangent" });

  j = valid_rbf_file();
  j["correction"]["damping_weights"].erase(0);
  expect_bad(j, { "bad.json: correction.damping_weights" });

  j = valid_rbf_file();
  j["correction"]["damping_slope"] = 0.1; // the older scalar slope besides the sorted ones
  expect_bad(j, { "bad.json: correction.damping_slope", "not both" });
  j = valid_rbf_file();
  j["correction"]["damping_slopes"] = Json::array({ 0.1, 0.2 });
  expect_bad(j, { "bad.json: correction.damping_slopes", "3 numbers" });

  // JSON has no NaN: nlohmann writes a NaN as null, and a hand-edited "NaN" is invalid JSON.
  j = valid_rbf_file();
  j["correction"]["weights"][2] = std::nan("");
  expect_bad(j, { "bad.json: correction.weights[2]", "finite" });
  j = valid_rbf_file();
  j["correction"]["weights"][2] = nullptr;
  expect_bad(j, { "bad.json: correction.weights[2]", "null" });

  j = valid_rbf_file();
  j["correction"]["damping_floor"] = "low";
  expect_bad(j, { "bad.json: correction.damping_floor", "number" });

  j = valid_rbf_file();
  j["correction"]["epsilon"] = -1.0;
  expect_bad(j, { "bad.json: correction.epsilon" }); // the RbfCorrection's own check, renamed

  j = valid_rbf_file();
  j["correction"]["type"] = "spline";
  expect_bad(j, { "bad.json: correction.type", "\"rbf\"" });

  j = valid_rbf_file();
  j["correction"]["wieghts"] = j["correction"]["weights"];
  expect_bad(j, { "bad.json: correction.wieghts", "weights" });

  j = valid_rbf_file();
  j["material"]["poisson"] = 0.7;
  expect_bad(j, { "bad.json: material.poisson" });

  MaterialFile nn;
  nn.material = k_nominal;
  nn.correction = std::make_shared<material::NnCorrection>(nn_parameters(1));
  j = material_file_to_json(nn);
  j["correction"]["layers"][1]["weight"].erase(0); // 5 × 6 then a 6-input layer
  j["correction"]["layers"][1]["bias"].erase(0);
  expect_bad(j, { "bad.json: correction.layers[2].weight" });
  j = material_file_to_json(nn);
  j["correction"]["input_scale"][3] = 0.0;
  expect_bad(j, { "bad.json: correction.input_scale", "> 0" });
  // A file of the former per-slot network (3 outputs) is refused with a pointed message.
  j = material_file_to_json(nn);
  j["correction"]["output_mean"] = Json::array({ 1.0, 2.0, 3.0 });
  expect_bad(j, { "bad.json: correction.output_mean", "number" });
  j = material_file_to_json(nn);
  j["correction"]["layers"][2]["weight"] = Json::array({ j["correction"]["layers"][2]["weight"][0],
      j["correction"]["layers"][2]["weight"][0], j["correction"]["layers"][2]["weight"][0] });
  j["correction"]["layers"][2]["bias"] = Json::array({ 0.0, 0.0, 0.0 });
  expect_bad(j, { "bad.json: correction.layers[2].weight", "expected 1" });
  // The network's damping correction is an RBF without elastic part.
  material::NnCorrection::Parameters damped = nn_parameters(1);
  damped.damping = std::make_shared<const material::RbfCorrection>(
      material::damping_part(material::RbfCorrection(rbf_parameters(4, 2))));
  nn.correction = std::make_shared<material::NnCorrection>(damped);
  j = material_file_to_json(nn);
  EXPECT_NO_THROW(parse_material_file(j, "ok.json"));
  j["correction"]["damping"]["weights"][1] = 100.0;
  expect_bad(j, { "bad.json: correction.damping", "elastic part" });
  j = material_file_to_json(nn);
  j["correction"]["damping"]["damping_weights"].erase(0);
  expect_bad(j, { "bad.json: correction.damping.damping_weights" });
  j = material_file_to_json(nn);
  j["correction"]["damping"]["type"] = "nn";
  expect_bad(j, { "bad.json: correction.damping.type", "\"rbf\"" });
}

TEST(MaterialFile, OlderScalarDampingSlopeReadsAsEqualSortedSlopes) {
  // Files written before the sorted slopes carry one slope a_d along Σσ − 3 = Σ (s_k − 1).
  Json j = valid_rbf_file();
  j["correction"].erase("damping_slopes");
  j["correction"]["damping_slope"] = 0.25;
  const auto file = parse_material_file(j, "old.json");
  const auto& c = dynamic_cast<const material::RbfCorrection&>(*file.correction);
  EXPECT_EQ(c.parameters().damping_slopes, Vec3::Constant(0.25));
}

TEST(MaterialFile, BrokenJsonNamesTheLine) {
  ScratchDir dir;
  std::ofstream(dir / "nan.json")
      << "{\"format\": \"elastolearn-material/1\",\n \"material\": {\"young\": NaN}}";
  expect_input_error([&] { read_material_file(dir / "nan.json"); }, { "nan.json:2:" });
  expect_input_error([&] { read_material_file(dir / "missing.json"); }, { "missing.json" });
}

TEST(MaterialFile, SceneMayReferenceAMaterialFile) {
  ScratchDir dir;
  fs::create_directories(dir / "materials");
  MaterialFile f;
  f.material = k_nominal;
  f.correction = std::make_shared<material::RbfCorrection>(rbf_parameters(5, 4));
  f.training_stretches.emplace();
  f.training_stretches->include(Vec3(1.03, 1.0, 0.97));
  write_material_file(dir / "materials" / "learned.json", f);
  const std::string scene = R"({"format": "elastolearn-scene/1",
    "mesh": {"type": "box", "size": [0.1, 0.02, 0.02], "cells": [2, 1, 1]},
    "material": "materials/learned.json", "time": {"dt": 0.01, "frames": 2}})";
  std::ofstream(dir / "scene.json") << scene;
  const SceneFile s = read_scene_file(dir / "scene.json");
  ASSERT_NE(s.scene.material.correction, nullptr);
  expect_same_function(*f.correction, *s.scene.material.correction);
  EXPECT_EQ(s.scene.material.elastic->name(), "corotated");
  ASSERT_TRUE(s.material_training_stretches.has_value()) << "simulate compares with it";
  EXPECT_EQ(s.material_training_stretches->max, Vec3(1.03, 1.0, 0.97));

  // The scene file and scene_material give the nominal JSON too (what `learn` saves a result
  // with).
  EXPECT_EQ(s.nominal_material, k_nominal);
  const Json scene_json = Json::parse(scene);
  EXPECT_EQ(scene_material(JsonObject(scene_json, "scene.json"), dir.path()).material, k_nominal);

  std::string missing = scene;
  missing.replace(missing.find("materials/learned.json"), 22, "materials/nothere.json");
  std::ofstream(dir / "missing.json") << missing;
  expect_input_error(
      [&] { read_scene_file(dir / "missing.json"); }, { "missing.json: material", "nothere.json" });

  f.material["young"] = -5;
  std::ofstream(dir / "materials" / "broken.json") << material_file_to_json(f).dump();
  std::string broken = scene;
  broken.replace(broken.find("materials/learned.json"), 22, "materials/broken.json");
  std::ofstream(dir / "broken_scene.json") << broken;
  expect_input_error(
      [&] { read_scene_file(dir / "broken_scene.json"); }, { "broken.json: material.young" });
}

TEST(MaterialFile, RbfTrustedStretchesRoundTrip) {
  // Energy kernels with a trusted interval: written as [min, max], read back to the same
  // function inside and beyond it; an unbounded end travels as null, a missing key is unbounded.
  auto p = rbf_parameters(3, 9);
  p.energy_kernels = true;
  p.quadratic[1] = 2 * p.quadratic[2];
  p.trusted.min = 0.85;
  MaterialFile f;
  f.material = k_nominal;
  f.correction = std::make_shared<material::RbfCorrection>(p);
  const Json j = material_file_to_json(f);
  EXPECT_EQ(j["correction"]["trusted_stretches"][0], 0.85);
  EXPECT_TRUE(j["correction"]["trusted_stretches"][1].is_null());
  const MaterialFile g = parse_material_file(Json::parse(j.dump()), "f.json");
  const auto& q = dynamic_cast<const material::RbfCorrection&>(*g.correction).parameters();
  EXPECT_EQ(q.trusted.min, 0.85);
  EXPECT_EQ(q.trusted.max, std::numeric_limits<double>::infinity());
  for (const Vec3& s : { Vec3(1.1, 1.0, 0.9), Vec3(1.2, 0.8, 0.6) })
    EXPECT_EQ(f.correction->correction(s, Vec3::Zero()), g.correction->correction(s, Vec3::Zero()));
  Json bad = j;
  bad["correction"]["trusted_stretches"] = Json::array({ 1.2 });
  expect_bad(bad, { "bad.json: correction.trusted_stretches", "[min, max]" });
  bad["correction"]["trusted_stretches"] = Json::array({ 1.2, 0.9 });
  expect_bad(bad, { "bad.json: correction.trusted_stretches", "min ≤ max" });
}

TEST(MaterialFile, RbfContinuationRoundTripsAndOlderFilesKeepTheEdgeHessian) {
  // "continuation" (with the bound's "nominal_stiffness" and "kept_stiffness") travels with the
  // trusted interval; a file without it (written before it existed) is continued with the edge's
  // whole Hessian, as it was when written. Beyond the lower edge (0.85) the test correction's
  // edge Hessian removes more than the bound allows, so the two continuations differ.
  auto p = rbf_parameters(3, 9);
  p.energy_kernels = true;
  p.quadratic[1] = 2 * p.quadratic[2];
  p.weights *= 50;
  p.trusted = { 0.85, 1.3, material::Continuation::bounded_softening };
  p.trusted.nominal_stiffness = 1e4 * (Mat3::Identity() + Mat3::Ones());
  p.trusted.kept_stiffness = 0.25;
  MaterialFile f;
  f.material = k_nominal;
  f.correction = std::make_shared<material::RbfCorrection>(p);
  const Json j = material_file_to_json(f);
  EXPECT_EQ(j["correction"]["continuation"], "bounded_softening");
  EXPECT_EQ(j["correction"]["kept_stiffness"], 0.25);
  const auto read = [](const Json& json) {
    return parse_material_file(Json::parse(json.dump()), "f.json").correction;
  };
  const auto bounded = read(j);
  const auto& q = dynamic_cast<const material::RbfCorrection&>(*bounded).parameters().trusted;
  EXPECT_EQ(q.nominal_stiffness, p.trusted.nominal_stiffness);
  EXPECT_EQ(q.kept_stiffness, 0.25);
  Json older = j;
  for (const char* key : { "continuation", "nominal_stiffness", "kept_stiffness" })
    older["correction"].erase(key);
  const auto hessian = read(older);
  EXPECT_EQ(
      dynamic_cast<const material::RbfCorrection&>(*hessian).parameters().trusted.continuation,
      material::Continuation::edge_hessian);
  const Vec3 beyond(1.0, 0.9, 0.5);
  EXPECT_EQ(
      f.correction->correction(beyond, Vec3::Zero()), bounded->correction(beyond, Vec3::Zero()));
  p.trusted.continuation = material::Continuation::edge_hessian;
  EXPECT_EQ(material::RbfCorrection(p).correction(beyond, Vec3::Zero()),
      hessian->correction(beyond, Vec3::Zero()));
  EXPECT_GT((bounded->correction(beyond, Vec3::Zero()) - hessian->correction(beyond, Vec3::Zero()))
                .norm(),
      1e-6 * hessian->correction(beyond, Vec3::Zero()).norm())
      << "the test needs an edge beyond the bound";
  Json bad = j;
  bad["correction"]["continuation"] = "linear";
  expect_bad(bad, { "bad.json: correction.continuation", "bounded_softening" });
  bad = j;
  bad["correction"].erase("nominal_stiffness");
  expect_bad(bad, { "bad.json: correction.nominal_stiffness" });
  bad = j;
  bad["correction"]["kept_stiffness"] = 2;
  expect_bad(bad, { "bad.json: correction", "kept_stiffness" });
}

TEST(MaterialFile, TheSmoothFormsRoundTripWithTheirWidth) {
  // "continuation": "smooth_expansion" or "smooth_clamp" with its "clamp_width": what learning
  // writes; read back it continues the correction exactly as written, beyond the interval too.
  for (const auto continuation :
      { material::Continuation::smooth_clamp, material::Continuation::smooth_expansion }) {
    const std::string name = material::continuation_name(continuation);
    SCOPED_TRACE(name);
    auto p = rbf_parameters(3, 9);
    p.energy_kernels = true;
    p.quadratic[1] = 2 * p.quadratic[2];
    p.trusted = { 0.85, 1.3, continuation };
    p.trusted.clamp_width = 0.07;
    p.trusted.nominal_stiffness = 1e4 * (Mat3::Identity() + Mat3::Ones());
    MaterialFile f;
    f.material = k_nominal;
    f.correction = std::make_shared<material::RbfCorrection>(p);
    const Json j = material_file_to_json(f);
    EXPECT_EQ(j["correction"]["continuation"], name);
    EXPECT_EQ(j["correction"]["clamp_width"], 0.07);
    const auto read = parse_material_file(Json::parse(j.dump()), "f.json").correction;
    const auto& q = dynamic_cast<const material::RbfCorrection&>(*read).parameters().trusted;
    EXPECT_EQ(q.continuation, continuation);
    EXPECT_EQ(q.clamp_width, 0.07);
    EXPECT_EQ(q.nominal_stiffness, p.trusted.nominal_stiffness);
    for (const Vec3& s : { Vec3(1.0, 0.9, 0.5), Vec3(1.33, 1.0, 0.95), Vec3(2.0, 1.4, 0.6) })
      EXPECT_EQ(f.correction->correction(s, Vec3::Zero()), read->correction(s, Vec3::Zero()));
    Json bad = j;
    bad["correction"].erase("clamp_width");
    expect_bad(bad, { "bad.json: correction.clamp_width" });
    bad = j;
    bad["correction"]["clamp_width"] = -1;
    expect_bad(bad, { "bad.json: correction", "clamp_width" });
  }
}
