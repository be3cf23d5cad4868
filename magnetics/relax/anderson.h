// Anderson mixing (type II, Walker & Ni 2011) for the outer fixed-point loop of
// the relaxation: x <- G(x) with residual f = G(x) - x.
#pragma once

#include <deque>
#include <vector>

namespace odemag {

class AndersonMixer {
 public:
  // depth: number of stored differences (0: plain mixing); mixing: beta.
  AndersonMixer(int depth, double mixing) : depth_(depth), mixing_(mixing) {}

  // Weights of the least-squares norm (one per component); empty: unweighted.
  void set_weights(std::vector<double> w) { weights_ = std::move(w); }

  // Replaces x by the next iterate, given the residual f at x.
  void next(std::vector<double>& x, const std::vector<double>& f);

  void reset() { xs_.clear(); fs_.clear(); }

 private:
  int depth_;
  double mixing_;
  std::vector<double> weights_;
  std::deque<std::vector<double>> xs_, fs_;
};

}  // namespace odemag
