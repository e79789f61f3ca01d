#include <elastolearn/core/error.hpp>
#include <elastolearn/material/elastic_model.hpp>

#include <cmath>
#include <sstream>

namespace elastolearn::material {

Lame Lame::from_young_poisson(double young, double poisson) {
  if (!std::isfinite(young) || !(young > 0)) {
    std::ostringstream os;
    os << "Young's modulus must be a finite positive number [Pa], got " << young;
    throw InputError("young", os.str());
  }
  if (!std::isfinite(poisson) || !(poisson > -1) || !(poisson < 0.5)) {
    std::ostringstream os;
    os << "Poisson ratio must satisfy -1 < nu < 0.5, got " << poisson;
    throw InputError("poisson", os.str());
  }
  Lame l;
  l.mu = young / (2 * (1 + poisson));
  l.lambda = young * poisson / ((1 + poisson) * (1 - 2 * poisson));
  return l;
}

} // namespace elastolearn::material
