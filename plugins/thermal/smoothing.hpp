#pragma once
// The smoothed indicator h of the paper (4.15-4.16) and the Robin coefficient h_ε it defines:
//
//   h(r) = 1 − 1/(1 + exp(4r/(r² − 1)))  on (−1, 1),   1 for r ≤ −1,   0 for r ≥ 1,
//   h_ε(d) = h(d/ε)/ε,                  dh_ε/dd = h′(d/ε)/ε².
//
// h is C^∞, decreasing, 0 ≤ h ≤ 1, h(0) = 1/2, h(−r) = 1 − h(r), ∫_{−1}^{1} h′ = −1. With d the signed
// distance to G (negative inside), h_ε = 1/ε deep in G (nearly Dirichlet), 0 outside the band (insulated).
namespace bodyfit::thermal {

/// h(r), computed as the logistic function of t = 4r/(r² − 1): no overflow near ±1.
double h(double r);
/// h′(r) = −σ(t)(1 − σ(t))·4(1 + r²)/(1 − r²)²; 0 outside (−1, 1) and wherever the exponential
/// factor underflows (before the rational factor can overflow).
double h_prime(double r);
/// h_ε(d) = h(d/ε)/ε. Throws InputError when ε ≤ 0.
double h_epsilon(double d, double epsilon);
/// dh_ε/dd = h′(d/ε)/ε². Throws InputError when ε ≤ 0.
double h_epsilon_prime(double d, double epsilon);

}  // namespace bodyfit::thermal
