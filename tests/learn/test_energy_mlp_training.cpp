// The energy network's training gradient (learn/energy_mlp_training.hpp): the double
// back-propagation matches central differences of the loss, and the chunked parallel sum gives
// the same numbers for any sample count, including fewer samples than chunks.
#include <elastolearn/learn/energy_mlp_training.hpp>

#include <gtest/gtest.h>

#include <random>

using namespace elastolearn;
using namespace elastolearn::learn;

namespace {

/// n random samples of a d-input network with m targets: inputs and targets N(0, 1), maps
/// N(0, 0.5²).
GradientSamples random_gradient_samples(int d, int m, int n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const auto fill = [&](MatX& a, double scale) {
    for (Eigen::Index i = 0; i < a.size(); ++i)
      a.data()[i] = scale * standard_normal(rng);
  };
  GradientSamples s { MatX(d, n), MatX(d * m, n), MatX(m, n) };
  fill(s.inputs, 1);
  fill(s.maps, 0.5);
  fill(s.targets, 1);
  return s;
}

/// The largest difference between `gradient` and central differences of gradient_loss over every
/// weight and bias of `net`, relative to the largest gradient entry.
double gradient_mismatch(BatchNormMlp net, const GradientSamples& s, const MlpGradient& gradient) {
  const double h = 1e-6;
  double largest = 0, mismatch = 0;
  const auto check = [&](double& parameter, double analytic) {
    const double kept = parameter;
    parameter = kept + h;
    const double up = gradient_loss(net, s);
    parameter = kept - h;
    const double down = gradient_loss(net, s);
    parameter = kept;
    largest = std::max(largest, std::abs(analytic));
    mismatch = std::max(mismatch, std::abs((up - down) / (2 * h) - analytic));
  };
  for (std::size_t k = 0; k < net.layers.size(); ++k) {
    auto& layer = net.layers[k];
    for (Eigen::Index i = 0; i < layer.weight.size(); ++i)
      check(layer.weight.data()[i], gradient.weights[k].data()[i]);
    // The output bias does not change the input gradient: its entry is 0 and stays so.
    for (Eigen::Index i = 0; i < layer.bias.size(); ++i)
      check(layer.bias[i], gradient.biases[k][i]);
  }
  return mismatch / largest;
}

} // namespace

TEST(EnergyMlpTraining, TheWeightGradientMatchesCentralDifferencesOfTheLoss) {
  for (const material::Activation activation :
      { material::Activation::Squareplus, material::Activation::Tanh }) {
    BatchNormMlp net = make_batch_norm_mlp(3, { 8, 8 }, 1, false, 7);
    net.activation = activation;
    const GradientSamples s = random_gradient_samples(3, 3, 37, 11);
    GradientLoss loss;
    const MlpGradient& g = loss.gradient(net, s);
    ASSERT_EQ(g.weights.size(), net.layers.size());
    // Central differences with h = 1e-6 on a loss of order 1 are good to ~1e-9 relative; the
    // second derivatives in the weight gradient make a wrong term show at order 1.
    EXPECT_LT(gradient_mismatch(net, s, g), 1e-6) << material::to_string(activation);
  }
}

TEST(EnergyMlpTraining, TheChunkedGradientDoesNotDependOnHowTheSamplesSplit) {
  const BatchNormMlp net = make_batch_norm_mlp(3, { 6 }, 1, false, 3);
  // Fewer samples than chunks leaves some chunks empty; they add nothing.
  for (const int n : { 1, 2, GradientLoss::kChunks + 1, 101 }) {
    const GradientSamples s = random_gradient_samples(3, 2, n, 5);
    GradientLoss loss;
    const MlpGradient g = loss.gradient(net, s);
    EXPECT_LT(gradient_mismatch(net, s, g), 1e-6) << n << " samples";
    // A second call with the same buffers gives the same numbers bit for bit.
    const MlpGradient& again = loss.gradient(net, s);
    for (std::size_t k = 0; k < g.weights.size(); ++k) {
      EXPECT_EQ(g.weights[k], again.weights[k]);
      EXPECT_EQ(g.biases[k], again.biases[k]);
    }
  }
}
