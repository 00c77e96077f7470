#pragma once
// A tabulated adhesive coefficient μ_a(p, v, T) for the interfacial law `table` (seed 001's adhesive
// friction laws are of this form: μ_a measured against contact pressure, sliding velocity and
// temperature). The CSV holds a full rectangular grid, one row per grid point, columns with units:
//   contact_pressure[MPa],sliding_velocity[m/min],temperature[C],mu_a
// An axis may hold a single value (μ_a then does not depend on it). Between grid points μ_a is
// trilinear (exact for a law linear in each input); outside the grid it is held at the nearest edge
// (constant extrapolation), never extrapolated.
#include <string>
#include <vector>

namespace mufric::contact {

class AdhesionTable {
 public:
  // Reads and checks the table; errors name the file, the row or the missing grid point.
  static AdhesionTable read(const std::string& path);
  // From axes (each strictly increasing, SI units) and values in axis order (pressure slowest):
  // mu[(i · velocities + j) · temperatures + k].
  AdhesionTable(std::vector<double> pressures, std::vector<double> velocities, std::vector<double> temperatures,
                std::vector<double> mu, std::string source = {});

  struct Value {
    double mu = 0.0;
    double dmu_dpressure = 0.0;  // 1/Pa, 0 where held at an edge in p
  };
  Value at(double pressure_pa, double velocity_m_per_s, double temperature_k) const;

  const std::string& source() const { return source_; }
  // The grid's range, for messages: "p 300–1300 MPa, v 1–200 m/min, T 25–900 °C".
  std::string range() const;

 private:
  std::vector<double> p_, v_, t_, mu_;
  std::string source_;
};

}  // namespace mufric::contact
