#pragma once
/// \file One recorded motion of the object being learned: the scene that produced it (the nominal
/// material, no correction) and its observations. Learning takes one or more (a training set,
/// io/training_set.hpp).
#include <elastolearn/observe/observation.hpp>
#include <elastolearn/sim/scene.hpp>

#include <string>

namespace elastolearn::learn {

struct Motion {
  std::string name; ///< for messages and the learned file (e.g. the observation file's path)
  sim::Scene scene; ///< nominal material, no correction
  observe::Observation observed; ///< scene.frames + 1 frames of scene.dt
};

} // namespace elastolearn::learn
