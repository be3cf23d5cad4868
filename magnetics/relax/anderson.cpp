#include "magnetics/relax/anderson.h"

#include <Eigen/Dense>

namespace odemag {

void AndersonMixer::next(std::vector<double>& x, const std::vector<double>& f) {
  const int n = static_cast<int>(x.size());
  xs_.push_back(x);
  fs_.push_back(f);
  if (static_cast<int>(xs_.size()) > depth_ + 1) {
    xs_.pop_front();
    fs_.pop_front();
  }
  const int m = static_cast<int>(xs_.size()) - 1;
  std::vector<double> next(n);
  for (int i = 0; i < n; ++i) next[i] = x[i] + mixing_ * f[i];
  if (m > 0) {
    // gamma = argmin | W (f - dF gamma) |, dF_j = f_{j+1} - f_j.
    Eigen::MatrixXd dF(n, m);
    Eigen::VectorXd rhs(n);
    for (int i = 0; i < n; ++i) {
      const double w = weights_.empty() ? 1.0 : weights_[i];
      rhs[i] = w * f[i];
      for (int j = 0; j < m; ++j) dF(i, j) = w * (fs_[j + 1][i] - fs_[j][i]);
    }
    const Eigen::VectorXd gamma = dF.colPivHouseholderQr().solve(rhs);
    if (gamma.allFinite()) {
      for (int j = 0; j < m; ++j)
        for (int i = 0; i < n; ++i)
          next[i] -= gamma[j] * ((xs_[j + 1][i] - xs_[j][i]) + mixing_ * (fs_[j + 1][i] - fs_[j][i]));
    }
  }
  x.swap(next);
}

}  // namespace odemag
