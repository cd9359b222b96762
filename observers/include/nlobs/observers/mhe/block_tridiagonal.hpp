#pragma once
// Solves H d = b for a symmetric positive definite block-tridiagonal H — the Gauss–Newton matrix
// of a moving-horizon problem over the states x_0..x_{m−1}, whose process terms couple only
// neighbours ([RWR98] exploit the same structure) — in O(m s³) instead of O((m s)³):
//   H = L Lᵀ,  L_ii L_iiᵀ = D_i − C_{i−1} C_{i−1}ᵀ,  C_i = E_i L_ii⁻ᵀ,
// with D_i = H(i, i) (s × s) and E_i = H(i + 1, i). Forward L z = b, backward Lᵀ d = z.
// Storage is reserved once (reserve): factor and solve allocate nothing for fixed-size blocks.
#include <Eigen/Cholesky>
#include <vector>

namespace nlobs::detail {

template <int S>
class BlockTridiagonalCholesky {
 public:
  using Block = Eigen::Matrix<double, S, S>;
  using Vector = Eigen::Matrix<double, S, 1>;

  // Room for `blocks` diagonal blocks of size `size` × `size`.
  void reserve(Eigen::Index blocks, Eigen::Index size) {
    llt_.clear();
    llt_.reserve(static_cast<std::size_t>(blocks));
    for (Eigen::Index i = 0; i < blocks; ++i) llt_.emplace_back(size);  // storage, unfactored
    coupling_.assign(static_cast<std::size_t>(blocks), Block::Zero(size, size));
    pivot_ = Block::Zero(size, size);
  }

  // Factors the first m blocks (diag[0..m−1], sub[0..m−2]); false when a pivot block is not
  // positive definite (H is not), the factor then unusable.
  bool factor(const std::vector<Block>& diag, const std::vector<Block>& sub, std::size_t m) {
    for (std::size_t i = 0; i < m; ++i) {
      pivot_ = diag[i];
      if (i > 0) pivot_.noalias() -= coupling_[i - 1] * coupling_[i - 1].transpose();
      llt_[i].compute(pivot_);
      if (llt_[i].info() != Eigen::Success) return false;
      if (i + 1 < m) {  // C_i L_iiᵀ = E_i
        coupling_[i] = sub[i];
        llt_[i].matrixU().template solveInPlace<Eigen::OnTheRight>(coupling_[i]);
      }
    }
    return true;
  }

  // b ← H⁻¹ b over the first m blocks of the last factor().
  void solve(std::vector<Vector>& b, std::size_t m) const {
    for (std::size_t i = 0; i < m; ++i) {
      if (i > 0) b[i].noalias() -= coupling_[i - 1] * b[i - 1];
      llt_[i].matrixL().solveInPlace(b[i]);
    }
    for (std::size_t i = m; i-- > 0;) {
      if (i + 1 < m) b[i].noalias() -= coupling_[i].transpose() * b[i + 1];
      llt_[i].matrixU().solveInPlace(b[i]);
    }
  }

 private:
  std::vector<Eigen::LLT<Block>> llt_;
  std::vector<Block> coupling_;  // C_i
  Block pivot_;
};

}  // namespace nlobs::detail
