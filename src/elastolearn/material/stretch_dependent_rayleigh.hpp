#pragma once
/// \file Rayleigh damping whose coefficients are splines of the element's largest principal
/// stretch σ₁ (paper 000 §7, "Bar Damping": α₁(σ₁) edited with a spline tool).
#include <elastolearn/material/damping_model.hpp>
#include <elastolearn/material/spline.hpp>

namespace elastolearn::material {

/// α₀(σ₁) [1/s] and α₁(σ₁) [s] as C¹ monotone cubic splines (constant outside their knots).
class StretchDependentRayleigh final : public DampingModel {
public:
    /// Throws InputError(where, ...) if a spline has a negative knot value (the monotone spline
    /// stays within its knot values, so a non-negative spline gives non-negative damping).
    StretchDependentRayleigh(
        CubicSpline alpha0, CubicSpline alpha1, const std::string& where = "damping");
    std::string name() const override { return "stretch_dependent_rayleigh"; }
    RayleighCoefficients coefficients(double max_stretch) const override;
    bool is_constant() const override { return false; }
    std::unique_ptr<DampingModel> clone() const override;

    /// dα₀/dσ₁ and dα₁/dσ₁ at σ₁ (for integrators that differentiate the damping force fully).
    RayleighCoefficients coefficient_derivatives(double max_stretch) const;
    const CubicSpline& alpha0() const { return m_alpha0; }
    const CubicSpline& alpha1() const { return m_alpha1; }

private:
    CubicSpline m_alpha0, m_alpha1;
};

} // namespace elastolearn::material
