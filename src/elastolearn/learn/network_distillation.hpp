#pragma once
/// \file The recipe's network stage (docs/learning_recipe.md, stage 5): the chosen RBF correction
/// distilled into the network correction of paper 000 §6.2 by sampling element states of the
/// training motion at several amplitudes (distillation_samples) and training on the teacher's
/// outputs there (distill_nn_correction). The recipe validates the result like every candidate
/// and keeps it only if it predicts the held-out data as well as its teacher.
#include <elastolearn/learn/nn_distillation.hpp>
#include <elastolearn/material/nn_correction.hpp>
#include <elastolearn/material/rbf_correction.hpp>
#include <elastolearn/sim/scene.hpp>

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace elastolearn::learn {

struct NetworkOptions {
  bool enabled = true; ///< false: the recipe keeps the RBF (`learn --no-network`)
  /// The network's kind; default: the energy network for an RBF with energy kernels (its N is a
  /// gradient, and the energy network keeps that: a symmetric tangent), the stress network
  /// otherwise.
  std::optional<material::NnKind> kind;
  /// Amplitudes at which the training motion is simulated with the teacher to sample states
  /// (scaled_motions): a larger motion than the recorded one covers the stretches a user's next
  /// motion reaches.
  std::vector<double> motion_scales { 0.5, 1.0, 2.0 };
  DistillationSampleOptions samples;
  /// Training of a stress network (an energy network uses energy_distillation_options()).
  NnDistillationOptions stress_training;
  /// Throws InputError("network.<field>" or "distillation.<field>", ...).
  void validate() const;
};

/// "auto" (nullopt), "energy" or "stress"; throws InputError(field, ...) for another name.
std::optional<material::NnKind> network_kind_from_name(
    const std::string& name, const std::string& field);

/// What a distillation did.
struct NetworkDistillation {
  std::shared_ptr<const material::NnCorrection> correction; ///< with the teacher's Δα₁
  material::NnKind kind = material::NnKind::Energy;
  DistillationSampleReport sampled;
  int motions = 0; ///< motion amplitudes simulated
  int training_states = 0;
  int validation_states = 0;
  int epochs = 0;
  double training_rms = 0; ///< the network's N against the teacher's [Pa], training split
  double validation_rms = 0; ///< idem, the distillation's held-out states [Pa]
  double teacher_rms = 0; ///< RMS of the teacher's N over the samples [Pa]
  double seconds_sampling = 0;
  double seconds_training = 0;
  /// One line: states, epochs, errors relative to the teacher, times.
  std::string describe() const;
};

/// Distil `teacher` on states of `scene` (its material is the nominal the teacher corrects; any
/// correction it has is replaced by the teacher) at options.motion_scales. An energy network takes
/// the teacher's tails as its polynomial (rbf_energy_polynomial), so that it extrapolates like the
/// teacher. Deterministic. Throws InputError for invalid options or when no state is sampled.
NetworkDistillation distil_network(
    const sim::Scene& scene, const material::RbfCorrection& teacher, const NetworkOptions& options);

} // namespace elastolearn::learn
