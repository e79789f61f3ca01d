#include <elastolearn/core/error.hpp>
#include <elastolearn/learn/banded_block_cholesky.hpp>

#include <Eigen/Cholesky>

#include <cmath>

namespace elastolearn::learn {

namespace {

/// Column offset of stored block (i + d, i) in the band storage.
Eigen::Index band_column(int i, int d, int r) {
  return (Eigen::Index(3) * i + d) * r;
}

} // namespace

BlockBandedMatrix::BlockBandedMatrix(int blocks, int block_size)
    : m_blocks(blocks)
    , m_r(block_size) {
  if (blocks < 1 || block_size < 1) {
    throw InputError("block-banded matrix",
        "needs at least one block of size ≥ 1, got " + std::to_string(blocks) + " blocks of size "
            + std::to_string(block_size));
  }
  m_band = MatX::Zero(m_r, band_column(m_blocks, 0, m_r));
}

Eigen::Block<MatX> BlockBandedMatrix::block(int i, int j) {
  ELASTOLEARN_CHECK(i >= j && i - j <= 2 && j >= 0 && i < m_blocks, "block outside the band");
  return m_band.block(0, band_column(j, i - j, m_r), m_r, m_r);
}

Eigen::Block<const MatX> BlockBandedMatrix::block(int i, int j) const {
  ELASTOLEARN_CHECK(i >= j && i - j <= 2 && j >= 0 && i < m_blocks, "block outside the band");
  return m_band.block(0, band_column(j, i - j, m_r), m_r, m_r);
}

VecX BlockBandedMatrix::multiply(ConstRef<VecX> x) const {
  ELASTOLEARN_CHECK(x.size() == size(), "BlockBandedMatrix::multiply: wrong vector size");
  VecX y = VecX::Zero(size());
  for (int j = 0; j < m_blocks; ++j) {
    const auto xj = x.segment(Eigen::Index(j) * m_r, m_r);
    y.segment(Eigen::Index(j) * m_r, m_r).noalias()
        += block(j, j).selfadjointView<Eigen::Lower>() * xj;
    for (int d = 1; d <= 2 && j + d < m_blocks; ++d) {
      const auto b = block(j + d, j);
      y.segment(Eigen::Index(j + d) * m_r, m_r).noalias() += b * xj;
      y.segment(Eigen::Index(j) * m_r, m_r).noalias()
          += b.transpose() * x.segment(Eigen::Index(j + d) * m_r, m_r);
    }
  }
  return y;
}

MatX BlockBandedMatrix::to_dense() const {
  MatX a = MatX::Zero(size(), size());
  for (int j = 0; j < m_blocks; ++j) {
    const Eigen::Index c = Eigen::Index(j) * m_r;
    a.block(c, c, m_r, m_r) = block(j, j).selfadjointView<Eigen::Lower>();
    for (int d = 1; d <= 2 && j + d < m_blocks; ++d) {
      const Eigen::Index row = Eigen::Index(j + d) * m_r;
      a.block(row, c, m_r, m_r) = block(j + d, j);
      a.block(c, row, m_r, m_r) = block(j + d, j).transpose();
    }
  }
  return a;
}

void BandedBlockCholesky::compute(const BlockBandedMatrix& a) {
  m_factored = false;
  m_blocks = a.m_blocks;
  m_r = a.m_r;
  m_l = a.m_band; // same layout; the factor overwrites it block by block
  const int r = m_r;
  auto L = [&](int i, int j) { return m_l.block(0, band_column(j, i - j, r), r, r); };
  for (int j = 0; j < m_blocks; ++j) {
    // Pivot block: A_jj minus the contributions of the two previous block columns. Only the lower
    // triangle of A_jj is read (the stored diagonal blocks may hold only their lower part).
    auto pivot = L(j, j);
    for (int d = 1; d <= 2 && j - d >= 0; ++d) {
      pivot.selfadjointView<Eigen::Lower>().rankUpdate(L(j, j - d), -1.0);
    }
    Eigen::LLT<Eigen::Ref<MatX>> llt(pivot); // in place: the lower triangle becomes L_jj
    if (llt.info() != Eigen::Success) {
      m_l.resize(0, 0);
      throw NotPositiveDefiniteError(j,
          "the matrix is not positive definite: pivot block " + std::to_string(j) + " of "
              + std::to_string(m_blocks) + " (unknowns " + std::to_string(Eigen::Index(j) * r)
              + ".." + std::to_string(Eigen::Index(j + 1) * r - 1)
              + ") lost positive definiteness");
    }
    pivot.triangularView<Eigen::StrictlyUpper>().setZero();
    const auto ljj_t = pivot.transpose().triangularView<Eigen::Upper>();
    if (j + 1 < m_blocks) {
      auto l1 = L(j + 1, j);
      if (j >= 1)
        l1.noalias() -= L(j + 1, j - 1) * L(j, j - 1).transpose();
      ljj_t.solveInPlace<Eigen::OnTheRight>(l1);
    }
    if (j + 2 < m_blocks) {
      auto l2 = L(j + 2, j);
      ljj_t.solveInPlace<Eigen::OnTheRight>(l2);
    }
  }
  m_factored = true;
}

void BandedBlockCholesky::solve_in_place(Eigen::Ref<VecX> b) const {
  ELASTOLEARN_CHECK(m_factored, "BandedBlockCholesky::solve before a successful compute");
  ELASTOLEARN_CHECK(b.size() == Eigen::Index(m_blocks) * m_r, "BandedBlockCholesky: wrong size");
  const int r = m_r;
  auto L = [&](int i, int j) { return m_l.block(0, band_column(j, i - j, r), r, r); };
  auto seg = [&](int i) { return b.segment(Eigen::Index(i) * r, r); };
  // Forward: L y = b.
  for (int j = 0; j < m_blocks; ++j) {
    auto yj = seg(j);
    for (int d = 1; d <= 2 && j - d >= 0; ++d)
      yj.noalias() -= L(j, j - d) * seg(j - d);
    L(j, j).triangularView<Eigen::Lower>().solveInPlace(yj);
  }
  // Backward: Lᵀ x = y.
  for (int j = m_blocks - 1; j >= 0; --j) {
    auto xj = seg(j);
    for (int d = 1; d <= 2 && j + d < m_blocks; ++d)
      xj.noalias() -= L(j + d, j).transpose() * seg(j + d);
    L(j, j).transpose().triangularView<Eigen::Upper>().solveInPlace(xj);
  }
}

VecX BandedBlockCholesky::solve(ConstRef<VecX> b) const {
  VecX x = b;
  solve_in_place(x);
  return x;
}

double BandedBlockCholesky::log_determinant() const {
  ELASTOLEARN_CHECK(m_factored, "BandedBlockCholesky::log_determinant before compute");
  double sum = 0;
  for (int j = 0; j < m_blocks; ++j)
    sum += m_l.block(0, band_column(j, 0, m_r), m_r, m_r).diagonal().array().log().sum();
  return 2 * sum;
}

} // namespace elastolearn::learn
