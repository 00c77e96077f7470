#pragma once
// One-dimensional B-spline bases, open or periodic, and their evaluation (Piegl & Tiller, The NURBS
// Book, 2nd ed. 1997: span search A2.1, basis functions A2.2, derivatives A2.3).
//
// A periodic basis of degree p on [lo, lo + T) has n functions and n knots t_0 = lo ≤ … ≤ t_{n-1}
// < lo + T per period; the knot sequence continues periodically, t_{j+n} = t_j + T, and the
// extended function N_i (i any integer) is N_{i mod n} shifted by floor(i/n) periods. Curves add a
// translation per period to their control points, so one interval of a rough profile y(x) with
// period L is a periodic curve with shift (L, 0); a closed curve has shift 0.
#include <vector>

#include <Eigen/Dense>

namespace mufric::spline {

// Knots closer than this fraction of the domain length count as one knot.
inline constexpr double kRelativeKnotTolerance = 1e-12;
// Highest degree supported (work arrays are sized for it); IGA uses 2–4.
inline constexpr int kMaxDegree = 10;
// Basis-function derivatives at a point, rows r = 0..n (n ≤ kMaxDegree), columns j = 0..p: fixed
// capacity, so an evaluation allocates nothing (contact searches evaluate curves millions of times).
using BasisDerivatives = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxDegree + 1, kMaxDegree + 1>;

class SplineBasis {
 public:
  // Open basis from a full knot vector: non-decreasing, at least 2(p+1) knots, no inner knot of
  // multiplicity above p + 1. Throws Error naming the problem.
  static SplineBasis open(int degree, std::vector<double> knots);
  // Clamped (open, end knots of multiplicity p+1), uniform: `spans` equal spans on [lo, hi].
  static SplineBasis open_uniform(int degree, int spans, double lo, double hi);
  // Periodic: one period of knots starting at lo, period T; needs at least p + 1 knots.
  static SplineBasis periodic(int degree, std::vector<double> period_knots, double period);
  static SplineBasis periodic_uniform(int degree, int spans, double lo, double hi);

  int degree() const { return degree_; }
  bool is_periodic() const { return periodic_; }
  int count() const;  // number of distinct basis functions (= control points)
  double lo() const;
  double hi() const;
  double period() const { return hi() - lo(); }
  // Open: the stored knot vector. Periodic: one period of knots.
  const std::vector<double>& knots() const { return knots_; }
  // Knot t_j of the (for periodic bases, infinitely extended) sequence.
  double knot(int j) const;
  // Distinct knot values in [lo, hi]: the element boundaries.
  std::vector<double> breakpoints() const;

  // A parameter located in the basis: the span k with t_k ≤ u < t_{k+1} (the last span includes
  // hi for open bases), and for periodic bases u reduced into [lo, hi) with the periods removed.
  struct Location {
    int span = 0;
    double u = 0.0;
    int periods = 0;  // original u = u + periods · T
  };
  Location locate(double u) const;  // A2.1 (binary search)
  // Global index and period offset of the p + 1 functions non-zero on span k: extended index
  // k − p + j for j = 0..p.
  int function_index(int span, int j) const;
  int function_period(int span, int j) const;
  // d^r N_{k−p+j}/du^r for r = 0..n, j = 0..p, at u in span k (A2.3); rows r, columns j. n ≤ kMaxDegree.
  BasisDerivatives derivatives(int span, double u, int n) const;
  // The p + 1 non-zero values (A2.2).
  Eigen::VectorXd values(int span, double u) const;

  // Greville abscissae (knot averages), one per function; periodic ones reduced into [lo, hi).
  std::vector<double> greville() const;
  // Function i's Greville abscissa, not reduced: increasing in i (control points of x(u) = u).
  double greville_abscissa(int i) const;
  // The same space with one more knot at u (inside the domain).
  SplineBasis with_knot(double u) const;
  // Degree p + 1 with every knot's multiplicity raised by one: contains this basis's space.
  SplineBasis elevated() const;
  // Multiplicity of the knot value u (0 if u is not a knot).
  int multiplicity(double u) const;

 private:
  SplineBasis(int degree, std::vector<double> knots, bool periodic, double period);
  double tolerance() const;
  int degree_ = 0;
  bool periodic_ = false;
  double period_ = 0.0;
  std::vector<double> knots_;
};

}  // namespace mufric::spline
