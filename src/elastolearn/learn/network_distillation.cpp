#include <elastolearn/core/error.hpp>
#include <elastolearn/core/timing.hpp>
#include <elastolearn/learn/network_distillation.hpp>

#include <cstdio>

namespace elastolearn::learn {

void NetworkOptions::validate() const {
  samples.validate();
  stress_training.validate();
  if (motion_scales.empty())
    throw InputError("network.motion_scales", "needs at least one motion amplitude");
  for (double s : motion_scales)
    if (!std::isfinite(s) || s <= 0)
      throw InputError(
          "network.motion_scales", "must be finite and positive (got " + std::to_string(s) + ")");
}

std::optional<material::NnKind> network_kind_from_name(
    const std::string& name, const std::string& field) {
  if (name == "auto")
    return std::nullopt;
  if (name == "energy")
    return material::NnKind::Energy;
  if (name == "stress")
    return material::NnKind::Stress;
  throw InputError(field, "must be auto, energy or stress (got '" + name + "')");
}

std::string NetworkDistillation::describe() const {
  char line[512];
  std::snprintf(line, sizeof line,
      "network (%s): %d + %d states (%d recorded of %ld, %d jittered; %d/%d motions completed), "
      "%d epochs; RMS relative to the RBF teacher: training %.2f %%, validation %.2f %% (teacher "
      "RMS %.4g Pa); sampling %.1f s, training %.1f s",
      material::to_string(kind).c_str(), training_states, validation_states, sampled.recorded,
      sampled.states_seen, sampled.jittered, sampled.scenes_completed, motions, epochs,
      100 * training_rms / teacher_rms, 100 * validation_rms / teacher_rms, teacher_rms,
      seconds_sampling, seconds_training);
  return line;
}

NetworkDistillation distil_network(const sim::Scene& scene, const material::RbfCorrection& teacher,
    const NetworkOptions& options) {
  options.validate();
  NetworkDistillation d;
  const auto start = Clock::now();
  // Within the teacher's trusted stretches: beyond them it is the continuation of its edge.
  DistillationSampleOptions sampling = options.samples;
  const material::TrustedStretches& trusted = teacher.parameters().trusted;
  sampling.stretch_min = std::max(sampling.stretch_min, trusted.min);
  sampling.stretch_max = std::min(sampling.stretch_max, trusted.max);
  const StressSamples samples
      = distillation_samples(scene, options.motion_scales, teacher, sampling, &d.sampled);
  d.seconds_sampling = seconds_since(start);
  d.motions = static_cast<int>(options.motion_scales.size());
  d.kind = options.kind.value_or(
      teacher.parameters().energy_kernels ? material::NnKind::Energy : material::NnKind::Stress);
  NnDistillationOptions training = d.kind == material::NnKind::Energy
      ? energy_distillation_options()
      : options.stress_training;
  training.kind = d.kind;
  if (d.kind == material::NnKind::Energy)
    training.energy_polynomial = rbf_energy_polynomial(teacher);
  const NnDistillationResult r = distill_nn_correction(samples, training);
  material::NnCorrection::Parameters network
      = with_teacher_damping(r.correction, teacher).parameters();
  if (d.kind == material::NnKind::Energy)
    network.trusted = trusted; // continued beyond the teacher's data like the teacher
  d.correction = std::make_shared<const material::NnCorrection>(std::move(network));
  d.training_states = r.training_samples;
  d.validation_states = r.validation_samples;
  d.epochs = r.training.epochs;
  d.training_rms = r.training_rms;
  d.validation_rms = r.validation_rms;
  d.teacher_rms = r.target_rms;
  d.seconds_training = r.training.seconds;
  return d;
}

} // namespace elastolearn::learn
