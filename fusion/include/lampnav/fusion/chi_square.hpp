#pragma once
// Chi-square distribution for the validation gates of the labeller and the EKF.

namespace lampnav::fusion {

// P(X <= x) for X ~ chi-square with `dof` degrees of freedom, dof 1 to 200 (finite series).
double chi_square_cdf(double x, int dof);
// The x with chi_square_cdf(x, dof) = p, for p in (0, 1); exact to 1e-10 by bisection.
double chi_square_quantile(double p, int dof);

}  // namespace lampnav::fusion
