#include <elastolearn/material/element_stress.hpp>

namespace elastolearn::material {

ElementStress element_stress(
    const ElementMaterial& material, const Vec3& stretches, const Vec3& stretch_rates) {
  const ElasticModel* elastic = material.elastic;
  const Correction* correction = material.correction;
  // The models' results are built in place and copied into `out` after the damping model's
  // call: copied at once, the load would stall on store forwarding (this is the simulator's
  // hot loop).
  StressPair nominal = elastic != nullptr ? StressPair { elastic->principal_stress(stretches),
    elastic->principal_stress_derivative(stretches) }
                                          : StressPair {};
  const RayleighCoefficients alpha = material.damping != nullptr
      ? material.damping->coefficients(stretches[0])
      : RayleighCoefficients {};
  ElementStress out;
  out.nominal = nominal;
  out.has_correction = correction != nullptr;
  out.alpha = alpha;
  out.mass_damping = corrected_mass_damping(alpha.alpha0, correction);
  if (material.stiffness_scale != 1.0) {
    out.nominal.stress *= material.stiffness_scale;
    out.nominal.d_stretches *= material.stiffness_scale;
  }
  if (correction != nullptr)
    out.correction = correction->correction_with_gradient(
        stretches, stretch_rates, out.correction_d_stretches, out.correction_d_rates);
  if (elastic != nullptr)
    out.alpha1_change
        = corrected_stiffness_damping(out.alpha.alpha1, correction, stretches) - out.alpha.alpha1;
  if (correction == nullptr)
    return out;
  // N(σ, 0) only where something damps it: a rate-dependent correction is evaluated again.
  if (out.has_damping()) {
    if (correction->depends_on_rates()) {
      Mat3 unused;
      out.correction_elastic.stress = correction->correction_with_gradient(
          stretches, Vec3::Zero(), out.correction_elastic.d_stretches, unused);
    } else {
      out.correction_elastic = { out.correction, out.correction_d_stretches };
    }
  } else {
    out.correction_elastic.stress.setZero();
    out.correction_elastic.d_stretches.setZero();
  }
  return out;
}

} // namespace elastolearn::material
