#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/material/elastic_model.hpp>

#include <cmath>

namespace elastolearn::material {

Lame Lame::from_young_poisson(double young, double poisson) {
  if (!std::isfinite(young) || !(young > 0))
    throw InputError(
        "young", "Young's modulus must be a finite positive number [Pa], got " + to_text(young));
  if (!std::isfinite(poisson) || !(poisson > -1) || !(poisson < 0.5))
    throw InputError(
        "poisson", "Poisson ratio must satisfy -1 < nu < 0.5, got " + to_text(poisson));
  Lame l;
  l.mu = young / (2 * (1 + poisson));
  l.lambda = young * poisson / ((1 + poisson) * (1 - 2 * poisson));
  return l;
}

} // namespace elastolearn::material
