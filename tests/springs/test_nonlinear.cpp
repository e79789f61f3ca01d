// Nonlinear springs (beyond the paper): learned from a nonlinear reference and compared on
// rope and cloth statics with the reference nonlinear mass-spring system.
#include <elastolearn/springs/stiffness.hpp>

#include <gtest/gtest.h>

using namespace elastolearn;
using namespace elastolearn::springs;

TEST(NonlinearSprings, CubicRopeAndClothStaticsMatchTheReference) {
  TrainingOptions t;
  t.law.kind = SpringLawKind::cubic;
  t.law.k = 100.0;
  t.law.k3 = 2000.0;
  LearnOptions o;
  o.features.degree = 3;
  const LearnedSpring spring = learn_spring(t, o);
  StiffnessOptions so;
  so.forces = { 5, 20, 50 };
  for (const LoadCase& load : { rope_load_case(5), cloth_load_case() }) {
    const StiffnessMeasurement ref = measure_stiffness(reference_factory(t.law, 0.01), load, so);
    LearnedSimulatorOptions sim;
    for (LearnedMode mode : { LearnedMode::corrected_explicit, LearnedMode::corrected_implicit }) {
      sim.mode = mode;
      const StiffnessMeasurement learned
          = measure_stiffness(learned_factory(spring, sim), load, so);
      ASSERT_TRUE(learned.converged && ref.converged) << learned.message << ref.message;
      for (std::size_t i = 0; i < ref.displacements.size(); ++i)
        // The cubic fit is exact to round-off (~1e-12 relative on Δv).
        EXPECT_NEAR(learned.displacements[i], ref.displacements[i], 1e-8 * ref.displacements[i]);
    }
    // Hardening: the secant stiffness grows with the force.
    EXPECT_GT(ref.stiffness.back(), ref.stiffness.front());
  }
}
