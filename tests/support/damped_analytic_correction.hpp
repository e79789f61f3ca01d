#pragma once
/// \file A test correction with every part a learned one can have: N = AnalyticCorrection
/// (a cubic in the stretches plus, if b ≠ 0, a stretch-rate viscous term) and a learned stiffness
/// damping Δα₁(σ) = δ + γ (σ₀ − 1).
#include <elastolearn/material/analytic_correction.hpp>
#include <elastolearn/material/correction.hpp>

#include <memory>
#include <string>

namespace elastolearn::test {

class DampedAnalyticCorrection final : public material::Correction {
  public:
  DampedAnalyticCorrection(material::AnalyticCorrection::Parameters n, double delta, double gamma)
      : m_n(n)
      , m_rates(n.b != 0)
      , m_delta(delta)
      , m_gamma(gamma) { }
  std::string name() const override { return "damped analytic"; }
  Vec3 correction(const Vec3& s, const Vec3& r) const override { return m_n.correction(s, r); }
  void correction_gradient(const Vec3& s, const Vec3& r, Mat3& ds, Mat3& dr) const override {
    m_n.correction_gradient(s, r, ds, dr);
  }
  bool depends_on_rates() const override { return m_rates; }
  double stiffness_damping(const Vec3& s) const override { return m_delta + m_gamma * (s[0] - 1); }
  std::unique_ptr<Correction> clone() const override {
    return std::make_unique<DampedAnalyticCorrection>(*this);
  }

  private:
  material::AnalyticCorrection m_n;
  bool m_rates;
  double m_delta, m_gamma;
};

} // namespace elastolearn::test
