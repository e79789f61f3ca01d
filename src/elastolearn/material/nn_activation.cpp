#include <elastolearn/material/nn_activation.hpp>

#include <array>
#include <utility>

namespace elastolearn::material {

namespace {

constexpr std::array<std::pair<Activation, const char*>, 6> k_names { {
    { Activation::Elu, "elu" },
    { Activation::Relu, "relu" },
    { Activation::Sigmoid, "sigmoid" },
    { Activation::Softplus, "softplus" },
    { Activation::Tanh, "tanh" },
    { Activation::Squareplus, "squareplus" },
} };

} // namespace

std::string to_string(Activation a) {
  for (const auto& [value, name] : k_names)
    if (value == a)
      return name;
  return "unknown";
}

std::optional<Activation> activation_from_string(const std::string& name) {
  for (const auto& [value, text] : k_names)
    if (name == text)
      return value;
  return std::nullopt;
}

} // namespace elastolearn::material
