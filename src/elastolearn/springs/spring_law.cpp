#include <elastolearn/springs/spring_law.hpp>

#include <elastolearn/core/error.hpp>

#include <cmath>

namespace elastolearn::springs {

namespace {
struct LawName {
  SpringLawKind kind;
  std::string_view name;
};
constexpr LawName k_law_names[] = { { SpringLawKind::linear, "linear" },
  { SpringLawKind::cubic, "cubic" }, { SpringLawKind::bilinear, "bilinear" } };

void require_coefficient(double value, const char* name) {
  if (!std::isfinite(value) || value < 0.0)
    throw InputError(std::string("spring law.") + name,
        "must be a finite value >= 0, got " + std::to_string(value));
}
} // namespace

std::string_view to_string(SpringLawKind kind) {
  for (const auto& entry : k_law_names)
    if (entry.kind == kind)
      return entry.name;
  return "unknown";
}

SpringLawKind spring_law_kind_from_string(const std::string& name, const std::string& where) {
  std::string valid;
  for (const auto& entry : k_law_names) {
    if (entry.name == name)
      return entry.kind;
    valid += (valid.empty() ? "" : ", ") + std::string(entry.name);
  }
  throw InputError(where, "unknown spring law '" + name + "' (expected one of: " + valid + ")");
}

void SpringLaw::validate() const {
  require_coefficient(k, "k");
  require_coefficient(c, "c");
  require_coefficient(k3, "k3");
  require_coefficient(k_compression, "k_compression");
  if (k == 0.0 && !(kind == SpringLawKind::cubic && k3 > 0.0))
    throw InputError("spring law.k", "stiffness must be > 0");
}

double SpringLaw::force(double e, double v) const {
  switch (kind) {
  case SpringLawKind::linear:
    return -k * e - c * v;
  case SpringLawKind::cubic:
    return -k * e - k3 * e * e * e - c * v;
  case SpringLawKind::bilinear:
    return -(e > 0.0 ? k : k_compression) * e - c * v;
  }
  return 0.0;
}

double SpringLaw::force_derivative_e(double e, double) const {
  switch (kind) {
  case SpringLawKind::linear:
    return -k;
  case SpringLawKind::cubic:
    return -k - 3.0 * k3 * e * e;
  case SpringLawKind::bilinear:
    return e >= 0.0 ? -k : -k_compression;
  }
  return 0.0;
}

double SpringLaw::force_derivative_v(double, double) const {
  return -c;
}

} // namespace elastolearn::springs
