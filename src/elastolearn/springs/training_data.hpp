#pragma once
/// \file Training data of paper 004 §2–3: a particle of mass m on a 1-D spring with the other end
/// fixed, integrated with semi-implicit Euler (Eqs. 1–2), sampled as (e, v) → (Δe, Δv).
#include <elastolearn/core/types.hpp>
#include <elastolearn/springs/spring_law.hpp>

#include <string_view>
#include <vector>

namespace elastolearn::springs {

/// How the 1-D phase space is sampled.
enum class SamplingKind {
  trajectories, ///< the paper: trajectories released from rest at each initial elongation
  phase_grid, ///< one semi-implicit Euler step from each point of a regular (e, v) grid;
              ///< needed when k·dt²/m ≥ 4, where the paper's trajectories diverge
};

/// "trajectories", "phase-grid".
std::string_view to_string(SamplingKind kind);
/// Inverse of to_string; throws InputError(where, ...).
SamplingKind sampling_kind_from_string(const std::string& name, const std::string& where);

/// Options of the 1-D data generator.
struct TrainingOptions {
  SpringLaw law; ///< reference force law the data come from
  double dt = 0.01; ///< step [s] (paper: 0.01, implied by its Table 1)
  double mass = 1.0; ///< particle mass [kg] (paper: 1)
  SamplingKind sampling = SamplingKind::trajectories;
  /// trajectories: initial elongations d [m] released at v = 0; phase_grid: the e range is
  /// [min, max] of these values.
  std::vector<double> elongations = { -0.5, -0.25, 0.25, 0.5 };
  int steps = 400; ///< trajectories: steps per trajectory; phase_grid: grid points per axis
  double max_speed = 0.0; ///< phase_grid: v range [−max, max]; 0 = amplitude·sqrt(k_max/m)

  /// Throws InputError("training options.<field>", ...) for invalid values, including a
  /// trajectory run that would diverge (k_max·dt²/m ≥ 4 for semi-implicit Euler).
  void validate() const;
};

/// Samples (e, v) → (Δe, Δv). Rows of `inputs` are (e, v), rows of `outputs` (Δe, Δv).
struct TrainingSet {
  MatX inputs; ///< N×2
  MatX outputs; ///< N×2
  double dt = 0.01;
  double mass = 1.0;
  SpringLaw law;
};

/// One semi-implicit Euler step of the 1-D particle (paper Eqs. 1–2, generalised to any law):
/// v⁺ = v + dt f(e, v)/m, e⁺ = e + dt v⁺. Returns (Δe, Δv).
Vec2 semi_implicit_step_1d(const SpringLaw& law, double dt, double mass, double e, double v);

/// Generate the training set. Throws InputError on invalid options.
TrainingSet generate_training_set(const TrainingOptions& options);

} // namespace elastolearn::springs
