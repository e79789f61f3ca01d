#pragma once
/// \file The reference model of paper 004 §2: a mass-spring system with a hand-written spring
/// force law, integrated with semi-implicit Euler. Used to generate comparisons only — the
/// learned simulators never call it.
#include <elastolearn/springs/explicit_stepper.hpp>
#include <elastolearn/springs/spring_law.hpp>

namespace elastolearn::springs {

/// Semi-implicit Euler mass-spring simulator: v⁺ = v + dt M⁻¹(Σ f_s(e, ė) u_s + F_ext) + dt g,
/// x⁺ = x + dt v⁺, with f_s from a `SpringLaw` and u_s the spring direction.
class ReferenceSimulator final : public ExplicitStepper {
  public:
  /// Throws InputError for an invalid law, dt ≤ 0 or loads of the wrong shape.
  ReferenceSimulator(SpringSystem system, SpringLaw law, double dt, const Loads& loads = {});

  void step(SpringState& state) override;
  std::string_view name() const override { return "reference"; }
  const SpringLaw& law() const { return m_law; }

  private:
  SpringLaw m_law;
};

} // namespace elastolearn::springs
