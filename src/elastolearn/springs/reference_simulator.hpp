#pragma once
/// \file The reference model of paper 004 §2: a mass-spring system with a hand-written spring
/// force law, integrated with semi-implicit Euler. Used to generate comparisons only — the
/// learned simulators never call it.
#include <elastolearn/springs/spring_law.hpp>
#include <elastolearn/springs/spring_system.hpp>

namespace elastolearn::springs {

/// Semi-implicit Euler mass-spring simulator: v⁺ = v + dt M⁻¹(Σ f_s(e, ė) u_s + F_ext) + dt g,
/// x⁺ = x + dt v⁺, with f_s from a `SpringLaw` and u_s the spring direction.
class ReferenceSimulator final : public SpringStepper {
  public:
  /// Throws InputError for an invalid law, dt ≤ 0 or loads of the wrong shape.
  ReferenceSimulator(SpringSystem system, SpringLaw law, double dt, const Loads& loads = {});

  void step(SpringState& state) override;
  void set_loads(const Loads& loads) override;
  const SpringSystem& system() const override { return m_system; }
  double dt() const override { return m_dt; }
  bool is_local() const override { return true; }
  std::string_view name() const override { return "reference"; }
  const SpringLaw& law() const { return m_law; }

  private:
  SpringSystem m_system;
  SpringLaw m_law;
  double m_dt;
  Positions m_external;
  Vec3 m_gravity = Vec3::Zero();
  Positions m_spring_forces; // s×3 scratch
  Positions m_node_forces; // n×3 scratch
};

} // namespace elastolearn::springs
