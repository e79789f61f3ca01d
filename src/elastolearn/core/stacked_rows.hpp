#pragma once
/// \file Stacking dense blocks one below the other.
#include <Eigen/Core>

#include <vector>

namespace elastolearn {

/// The parts one below the other (VecX or MatX of equal column counts; `columns` columns when
/// there are no parts).
template <typename Dense>
Dense stacked_rows(const std::vector<Dense>& parts, Eigen::Index columns = 1) {
  Eigen::Index rows = 0;
  for (const Dense& p : parts)
    rows += p.rows();
  Dense out(rows, parts.empty() ? columns : parts.front().cols());
  rows = 0;
  for (const Dense& p : parts) {
    out.middleRows(rows, p.rows()) = p;
    rows += p.rows();
  }
  return out;
}

} // namespace elastolearn
