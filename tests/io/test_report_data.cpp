// The report's plot data: what is not measured is null (never a made-up number), the candidates
// carry their labels and the choice, and the correction curves hold the learned and true
// corrections on the same samples.
#include <elastolearn/io/report_data.hpp>
#include <elastolearn/material/analytic_correction.hpp>
#include <elastolearn/material/corotated.hpp>
#include <elastolearn/material/neohookean.hpp>
#include <elastolearn/material/rayleigh_damping.hpp>

#include <gtest/gtest.h>

#include <cmath>

namespace elastolearn::io {
namespace {

TEST(ReportData, ConvergenceHasNullWhereNothingWasMeasured) {
  learn::ErrorSummary error;
  error.rms = 0.1;
  error.max = 0.2;
  learn::SpaceTimeStages stages;
  stages.control_force_rms = 3;
  stages.modes = 8;
  const learn::LoopRecord loop { 0, learn::ForwardOutcome::completed(error, 1), stages };
  const learn::LoopRecord diverged { 1, learn::ForwardOutcome::diverged("frame 3", 1),
    learn::DampedUpdate {} };
  const learn::ForwardFitRecord fit { 2, learn::ForwardOutcome::completed(error, 1), true, 8 };
  const learn::LoopRecord check { 3, learn::ForwardOutcome::completed(error, 1),
    learn::LoopEnd {} };
  const nlohmann::json c = convergence_json({ loop, diverged, fit, check });
  EXPECT_EQ(c.at("iteration"), nlohmann::json({ 0, 1, 2, 3 }));
  EXPECT_EQ(c.at("completed"), nlohmann::json({ true, false, true, true }));
  EXPECT_EQ(c.at("forward_rms_m"), nlohmann::json({ 0.1, nullptr, 0.1, 0.1 }));
  EXPECT_EQ(c.at("control_force_rms_N"), nlohmann::json({ 3.0, nullptr, nullptr, nullptr }))
      << "only the trajectory stages measure control forces";
  EXPECT_EQ(c.at("forward_fit"), nlohmann::json({ false, false, true, false }));
}

TEST(ReportData, CandidatesCarryLabelsAndTheChoice) {
  learn::RecipeResult r;
  learn::Candidate nominal;
  nominal.completed = true;
  nominal.validation.rms = 0.3;
  learn::Candidate loop;
  loop.kind = learn::CandidateKind::Loop;
  loop.iteration = 3;
  loop.completed = true;
  loop.validation.rms = 0.01;
  learn::Candidate fit;
  fit.kind = learn::CandidateKind::ForwardFit;
  fit.iteration = 7;
  fit.completed = false;
  r.candidates = { nominal, loop, fit };
  r.chosen = 1;
  r.validation_data = "last 20 % of frames of bar";
  const nlohmann::json j = candidates_json(r);
  EXPECT_EQ(j.at("validation_data"), "last 20 % of frames of bar");
  const auto& rows = j.at("rows");
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0].at("label"), "nominal");
  EXPECT_EQ(rows[1].at("label"), "loop 3");
  EXPECT_EQ(rows[2].at("label"), "forward fit 7");
  EXPECT_TRUE(rows[1].at("chosen").get<bool>());
  EXPECT_FALSE(rows[0].at("chosen").get<bool>());
  EXPECT_TRUE(rows[2].at("validation_rms_m").is_null()) << "it diverged";
  EXPECT_DOUBLE_EQ(rows[1].at("validation_rms_m").get<double>(), 0.01);
}

TEST(ReportData, CorrectionCurvesCompareLearnedAndTrue) {
  fem::MaterialModel learned;
  learned.elastic
      = std::make_shared<material::CorotatedModel>(material::Lame::from_young_poisson(1e6, 0.4));
  learned.damping = std::make_shared<material::RayleighDamping>(0.0, 0.01);
  learned.correction = std::make_shared<material::AnalyticCorrection>(
      material::AnalyticCorrection::Parameters { 1e6, 0, 0 });
  material::StretchRange training;
  training.include(Vec3(1.05, 1, 0.98));
  training.include(Vec3(1, 1, 1));

  const nlohmann::json without = correction_curves_json(learned, nullptr, &training);
  EXPECT_TRUE(without.at("uniaxial").at("truth_axial").is_null());
  EXPECT_FALSE(without.at("has_truth").get<bool>());
  const auto& u = without.at("uniaxial");
  const auto s = u.at("stretch").get<std::vector<double>>();
  // Three times the training's largest deviation from 1 (0.05) on each side.
  EXPECT_NEAR(s.front(), 0.85, 1e-12);
  EXPECT_NEAR(s.back(), 1.15, 1e-12);
  const auto axial = u.at("learned_axial").get<std::vector<double>>();
  for (std::size_t i = 0; i < s.size(); ++i)
    EXPECT_NEAR(axial[i], 1e6 * std::pow(s[i] - 1, 3), 1e-6) << s[i];
  const auto inside = u.at("inside").get<std::vector<bool>>();
  for (std::size_t i = 0; i < s.size(); ++i)
    EXPECT_EQ(inside[i], s[i] >= 0.98 && s[i] <= 1.05) << s[i];

  fem::MaterialModel truth = learned;
  truth.correction = nullptr;
  truth.elastic
      = std::make_shared<material::NeoHookeanModel>(material::Lame::from_young_poisson(1e6, 0.4));
  truth.damping = std::make_shared<material::RayleighDamping>(0.0, 0.02);
  const nlohmann::json with = correction_curves_json(learned, &truth, &training);
  const auto truth_axial = with.at("uniaxial").at("truth_axial").get<std::vector<double>>();
  for (std::size_t i = 0; i < s.size(); ++i) {
    const Vec3 sigma = s[i] >= 1 ? Vec3(s[i], 1, 1) : Vec3(1, 1, s[i]);
    const int axis = s[i] >= 1 ? 0 : 2;
    const double expected = truth.elastic->principal_stress(sigma)[axis]
        - learned.elastic->principal_stress(sigma)[axis];
    EXPECT_NEAR(truth_axial[i], expected, 1e-6 * (1 + std::abs(expected)));
  }
  EXPECT_EQ(with.at("damping").at("truth_alpha1").get<std::vector<double>>(),
      std::vector<double>(s.size(), 0.02));
  EXPECT_EQ(with.at("damping").at("nominal_alpha1").get<std::vector<double>>(),
      std::vector<double>(s.size(), 0.01));
  EXPECT_EQ(with.at("deformation_scale").size(), 6u);
}

} // namespace
} // namespace elastolearn::io
