#include <elastolearn/springs/paper_tables.hpp>

#include <cmath>
#include <limits>

namespace elastolearn::springs {

namespace {
/// Index of k among the paper's stiffnesses, or −1.
int paper_index(double k) {
  for (std::size_t i = 0; i < paper004::stiffness.size(); ++i)
    if (paper004::stiffness[i] == k)
      return static_cast<int>(i);
  return -1;
}
constexpr double k_nan = std::numeric_limits<double>::quiet_NaN();

SpringLaw linear_law(double k, double c) {
  SpringLaw law;
  law.kind = SpringLawKind::linear;
  law.k = k;
  law.c = c;
  return law;
}
} // namespace

LearnedSpring learn_paper_spring(double k, const ExperimentOptions& options) {
  TrainingOptions t;
  t.law = linear_law(k, options.c);
  t.dt = options.dt;
  t.mass = options.mass;
  for (double& e : t.elongations)
    e *= options.rest_length;
  if (k * options.dt * options.dt / options.mass >= 3.5)
    t.sampling = SamplingKind::phase_grid;
  return learn_spring(t);
}

std::vector<Table1Row> reproduce_table1(const ExperimentOptions& options) {
  std::vector<Table1Row> rows;
  for (double k : options.stiffnesses) {
    const LearnedSpring spring = learn_paper_spring(k, options);
    const LoadCase load = rope_load_case(2, options.rest_length);
    Table1Row row;
    row.k = k;
    const int i = paper_index(k);
    row.paper = i >= 0 ? paper004::table1_k_reg[i] : k_nan;
    row.learned
        = measure_stiffness(learned_factory(spring, options.simulation), load, options.stiffness);
    row.reference = measure_stiffness(
        reference_factory(linear_law(k, options.c), options.dt), load, options.stiffness);
    rows.push_back(std::move(row));
  }
  return rows;
}

std::vector<Table2Row> reproduce_table2(
    const ExperimentOptions& options, const std::vector<int>& nodes) {
  std::vector<Table2Row> rows;
  for (int n : nodes)
    for (double k : options.stiffnesses) {
      const LearnedSpring spring = learn_paper_spring(k, options);
      const LoadCase load = rope_load_case(n, options.rest_length);
      Table2Row row;
      row.nodes = n;
      row.k = k;
      const int i = paper_index(k);
      int r = -1;
      for (std::size_t j = 0; j < paper004::table2_nodes.size(); ++j)
        if (paper004::table2_nodes[j] == n)
          r = static_cast<int>(j);
      row.paper = (i >= 0 && r >= 0) ? paper004::table2_k[r][i] : k_nan;
      row.learned
          = measure_stiffness(learned_factory(spring, options.simulation), load, options.stiffness);
      row.reference = measure_stiffness(
          reference_factory(linear_law(k, options.c), options.dt), load, options.stiffness);
      rows.push_back(std::move(row));
    }
  return rows;
}

std::vector<Table3Row> reproduce_table3(const ExperimentOptions& options) {
  std::vector<Table3Row> rows;
  for (double k : options.stiffnesses) {
    const LearnedSpring spring = learn_paper_spring(k, options);
    const LoadCase load = cloth_load_case(5, 5, options.rest_length);
    Table3Row row;
    row.k = k;
    const int i = paper_index(k);
    row.paper_reference = i >= 0 ? paper004::table3_k_msm[i] : k_nan;
    row.paper_learned = i >= 0 ? paper004::table3_k_reg[i] : k_nan;
    row.learned
        = measure_stiffness(learned_factory(spring, options.simulation), load, options.stiffness);
    row.reference = measure_stiffness(
        reference_factory(linear_law(k, options.c), options.dt), load, options.stiffness);
    rows.push_back(std::move(row));
  }
  return rows;
}

} // namespace elastolearn::springs
