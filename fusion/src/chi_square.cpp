#include "lampnav/fusion/chi_square.hpp"

#include <cmath>
#include <stdexcept>

namespace lampnav::fusion {

double chi_square_cdf(double x, int dof) {
  if (dof < 1 || dof > 200) throw std::invalid_argument("chi_square_cdf: dof must be 1 to 200");
  if (x <= 0) return 0.0;
  const double h = x / 2;
  // Even dof: 1 - e^-h sum_{k < dof/2} h^k / k!. Odd dof: erf(sqrt h) minus the series in
  // half-integer powers, 2 e^-h sum_{k=1}^{(dof-1)/2} h^(k - 1/2) / Gamma(k + 1/2).
  if (dof % 2 == 0) {
    double term = 1, sum = 0;
    for (int k = 0; k < dof / 2; ++k) {
      sum += term;
      term *= h / (k + 1);
    }
    return 1 - std::exp(-h) * sum;
  }
  double sum = 0, term = std::sqrt(h) / std::tgamma(1.5);
  for (int k = 1; k <= (dof - 1) / 2; ++k) {
    sum += term;
    term *= h / (k + 0.5);
  }
  return std::erf(std::sqrt(h)) - std::exp(-h) * sum;
}

double chi_square_quantile(double p, int dof) {
  if (!(p > 0 && p < 1)) throw std::invalid_argument("chi_square_quantile: p must be in (0, 1)");
  double lo = 0, hi = 1;
  while (chi_square_cdf(hi, dof) < p) hi *= 2;
  for (int i = 0; i < 200 && hi - lo > 1e-12; ++i) {
    const double mid = 0.5 * (lo + hi);
    (chi_square_cdf(mid, dof) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace lampnav::fusion
