#pragma once
/// \file Symmetric positive-definite block-banded matrices and their Cholesky factorisation, for
/// the reduced Gauss–Newton normal equations of the sparse reduced space-time optimisation
/// (paper 000 §5.1, Eqs. 2–4; DESIGN.md "learning loop" step 4). The physics residual at step i
/// couples z_{i−1}, z_i, z_{i+1}, so JᵀJ has nonzero blocks only within two blocks of the
/// diagonal: factor and solve in O(T r³) time and O(T r²) memory instead of a dense solve.
#include <elastolearn/core/types.hpp>

#include <stdexcept>
#include <string>

namespace elastolearn::learn {

/// A symmetric T×T block matrix with r×r blocks and block bandwidth 2: only the blocks (i, i),
/// (i+1, i) and (i+2, i) of the lower triangle are stored (the upper ones are their transposes).
/// Unknown j of block i is row i·r + j of the full (T·r)×(T·r) matrix. Of a diagonal block only
/// the lower triangle is read, so assembling it in full or lower-only is equally valid.
class BlockBandedMatrix {
  public:
  /// All stored blocks zero. Throws InputError if blocks < 1 or block_size < 1.
  BlockBandedMatrix(int blocks, int block_size);

  int blocks() const { return m_blocks; }
  int block_size() const { return m_r; }
  /// T·r.
  Eigen::Index size() const { return Eigen::Index(m_blocks) * m_r; }

  /// The stored lower block (i, j), 0 ≤ i − j ≤ 2, i < T (a writable view into the band).
  Eigen::Block<MatX> block(int i, int j);
  Eigen::Block<const MatX> block(int i, int j) const;

  /// Set every stored block to zero (keeps the storage: for re-assembly each Gauss–Newton step).
  void set_zero() { m_band.setZero(); }
  /// y = A x (x of length T·r).
  VecX multiply(ConstRef<VecX> x) const;
  /// The full dense symmetric matrix (for tests and small problems).
  MatX to_dense() const;

  private:
  friend class BandedBlockCholesky;
  int m_blocks;
  int m_r;
  /// r × (3·T·r): column block 3i + d holds block (i + d, i), d = 0, 1, 2 (unused past the end).
  MatX m_band;
};

/// Thrown by BandedBlockCholesky::compute when the matrix is not (numerically) positive definite.
class NotPositiveDefiniteError : public std::runtime_error {
  public:
  NotPositiveDefiniteError(int block, const std::string& what)
      : std::runtime_error(what)
      , m_block(block) { }
  /// The block row (time step) whose pivot block failed.
  int block() const { return m_block; }

  private:
  int m_block;
};

/// A = L Lᵀ with L block lower-triangular of the same band (blocks (i,i), (i+1,i), (i+2,i)):
///   L_jj L_jjᵀ = A_jj − L_{j,j−1} L_{j,j−1}ᵀ − L_{j,j−2} L_{j,j−2}ᵀ
///   L_{j+1,j} = (A_{j+1,j} − L_{j+1,j−1} L_{j,j−1}ᵀ) L_jj⁻ᵀ,   L_{j+2,j} = A_{j+2,j} L_jj⁻ᵀ
/// (no fill-in outside the band). Factor once, then solve any number of right-hand sides;
/// compute() reuses the storage when called again with a matrix of the same size.
class BandedBlockCholesky {
  public:
  BandedBlockCholesky() = default;
  /// Factor `a`. Throws NotPositiveDefiniteError naming the first block whose pivot block is
  /// not positive definite (the matrix is then singular or indefinite); the object is then empty.
  explicit BandedBlockCholesky(const BlockBandedMatrix& a) { compute(a); }
  void compute(const BlockBandedMatrix& a);

  bool factored() const { return m_factored; }
  /// x with A x = b (b of length T·r). Requires factored().
  VecX solve(ConstRef<VecX> b) const;
  /// Overwrite b (length T·r) with A⁻¹ b, without allocating.
  void solve_in_place(Eigen::Ref<VecX> b) const;
  /// log det A = 2 Σ log diag(L) (e.g. for checking conditioning).
  double log_determinant() const;

  private:
  int m_blocks = 0;
  int m_r = 0;
  MatX m_l; ///< the factor, stored like BlockBandedMatrix::m_band
  bool m_factored = false;
};

} // namespace elastolearn::learn
