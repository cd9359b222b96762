#pragma once
// The explicit instantiations for a model of catalogue.hpp's high-gain list (autonomous, one
// output): its MVT observer, its high-gain observer and its Taylor-mode observability maps at the
// orders `lowest` = max(2, n)…8 (a literal: the order list is spelled by the preprocessor).
#include "instantiate_mvt.hpp"
#include "nlobs/observers/high_gain/high_gain_observer.hpp"
#include "nlobs/observers/high_gain/taylor_observability_map.hpp"

#define NLOBS_INSTANTIATE_TAYLOR_MAP(M, N) template class TaylorObservabilityMap<M, N>;
#define NLOBS_INSTANTIATE_HIGH_GAIN_MODEL(M, lowest)                                         \
  static_assert(lowest == (M::kStates > 2 ? M::kStates : 2),                                 \
                "catalogue.hpp's lowest order for " #M " must be max(2, n)");                \
  template class MvtObserver<M>;                                                             \
  template class HighGainObserver<M>;                                                        \
  template std::shared_ptr<ObservabilityMap> make_taylor_observability_map<M>(const M&, int, \
                                                                              std::string);  \
  NLOBS_TAYLOR_ORDERS_FROM(NLOBS_INSTANTIATE_TAYLOR_MAP, M, lowest)
