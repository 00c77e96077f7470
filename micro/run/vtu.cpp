#include "micro/run/vtu.hpp"

#include <iomanip>
#include <sstream>

#include "common/files.hpp"

namespace mufric::run {
namespace {

constexpr int kSamplesPerElement = 4;  // sub-cells per element and direction
constexpr int kVtkQuad = 9, kVtkPolyLine = 4;

// Linear interpolation of the contact pressure along the surface's reference x.
double pressure_at(const contact::ContactState& c, double x) {
  if (c.point_x.empty()) return 0.0;
  const auto it = std::lower_bound(c.point_x.begin(), c.point_x.end(), x);
  if (it == c.point_x.begin()) return c.point_pressure.front();
  if (it == c.point_x.end()) return c.point_pressure.back();
  const auto k = static_cast<size_t>(it - c.point_x.begin());
  const double t = (x - c.point_x[k - 1]) / (c.point_x[k] - c.point_x[k - 1]);
  return c.point_pressure[k - 1] + t * (c.point_pressure[k] - c.point_pressure[k - 1]);
}

// The sampled grid of a patch (nu × nv points, row by row) as VTK points and quadrilateral cells,
// with the file's header; the caller continues with the point data.
void write_grid(std::ostringstream& out, const std::vector<Eigen::Vector2d>& points, int nu, int nv) {
  const int cells = (nu - 1) * (nv - 1);
  out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      << "<UnstructuredGrid><Piece NumberOfPoints=\"" << nu * nv << "\" NumberOfCells=\"" << cells << "\">\n"
      << "<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (const auto& x : points) out << x.x() << " " << x.y() << " 0\n";
  out << "</DataArray></Points>\n<Cells><DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">\n";
  for (int j = 0; j + 1 < nv; ++j) {
    for (int i = 0; i + 1 < nu; ++i) {
      const int a = i + nu * j;
      out << a << " " << a + 1 << " " << a + 1 + nu << " " << a + nu << "\n";
    }
  }
  out << "</DataArray><DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">\n";
  for (int c = 1; c <= cells; ++c) out << 4 * c << "\n";
  out << "</DataArray><DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (int c = 0; c < cells; ++c) out << kVtkQuad << "\n";
  out << "</DataArray></Cells>\n";
}

// The parameter of sample k along a direction with element boundaries b.
double sample_parameter(const std::vector<double>& b, int k) {
  const int e = std::min(k / kSamplesPerElement, static_cast<int>(b.size()) - 2);
  return b[static_cast<size_t>(e)] +
         (b[static_cast<size_t>(e) + 1] - b[static_cast<size_t>(e)]) * (k - e * kSamplesPerElement) / kSamplesPerElement;
}

}  // namespace

void write_chip_vtu(const std::string& path, const solid::SolidProblem& problem, const Eigen::VectorXd& u,
                    const contact::ContactState& contact) {
  const auto& space = problem.space();
  const auto& patch = space.patch();
  const auto bu = patch.u_basis().breakpoints(), bv = patch.v_basis().breakpoints();
  const int nu = static_cast<int>(bu.size() - 1) * kSamplesPerElement + 1;
  const int nv = static_cast<int>(bv.size() - 1) * kSamplesPerElement + 1;
  // Element averages of the quadrature-point history.
  std::vector<double> plastic(static_cast<size_t>(space.element_count()), 0.0), temperature(plastic), count(plastic);
  for (size_t q = 0; q < space.quadrature().size(); ++q) {
    const auto e = static_cast<size_t>(space.quadrature()[q].element);
    plastic[e] += problem.states()[q].equivalent_plastic_strain;
    temperature[e] += problem.states()[q].temperature;
    count[e] += 1.0;
  }
  std::vector<Eigen::Vector2d> displacement, points;
  std::vector<double> pressure;
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      const double pu = sample_parameter(bu, i), pv = sample_parameter(bv, j);
      const Eigen::Vector2d x = patch.point(pu, pv), d = space.displacement(u, pu, pv);
      displacement.push_back(d);
      points.push_back(x + d);
      pressure.push_back(j == nv - 1 ? pressure_at(contact, x.x()) : 0.0);
    }
  }
  std::ostringstream out;
  out << std::setprecision(10);
  write_grid(out, points, nu, nv);
  out << "<PointData Vectors=\"displacement\">\n"
      << "<DataArray type=\"Float64\" Name=\"displacement\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (const auto& d : displacement) out << d.x() << " " << d.y() << " 0\n";
  out << "</DataArray><DataArray type=\"Float64\" Name=\"contact_pressure\" format=\"ascii\">\n";
  for (const double p : pressure) out << p << "\n";
  out << "</DataArray></PointData>\n<CellData>\n";
  const int elements_u = static_cast<int>(bu.size()) - 1;
  auto element_of_cell = [&](int i, int j) {
    return static_cast<size_t>(i / kSamplesPerElement + elements_u * (j / kSamplesPerElement));
  };
  for (const auto& [name, values] : {std::pair<const char*, const std::vector<double>*>{"equivalent_plastic_strain", &plastic},
                                     std::pair<const char*, const std::vector<double>*>{"temperature", &temperature}}) {
    out << "<DataArray type=\"Float64\" Name=\"" << name << "\" format=\"ascii\">\n";
    for (int j = 0; j + 1 < nv; ++j) {
      for (int i = 0; i + 1 < nu; ++i) {
        const size_t e = element_of_cell(i, j);
        out << (*values)[e] / std::max(count[e], 1.0) << "\n";
      }
    }
    out << "</DataArray>\n";
  }
  out << "</CellData>\n</Piece></UnstructuredGrid></VTKFile>\n";
  write_file_atomically(path, out.str());
}

void write_film_vtu(const std::string& path, const fluid::NavierStokes& film) {
  const fluid::FluidSpace& space = film.space();
  const auto bu = space.patch().u_basis().breakpoints(), bv = space.patch().v_basis().breakpoints();
  const int nu = static_cast<int>(bu.size() - 1) * kSamplesPerElement + 1;
  const int nv = static_cast<int>(bv.size() - 1) * kSamplesPerElement + 1;
  std::vector<Eigen::Vector2d> points, velocity;
  std::vector<double> pressure;
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      // The last column closes the periodic interval: its parameter is one period on (x = u + L).
      const double pu = i == nu - 1 ? bu.back() - 1e-12 * (bu.back() - bu.front()) : sample_parameter(bu, i);
      const fluid::ParametricPoint p = space.at(pu, sample_parameter(bv, j));
      points.push_back(space.map(p).position);
      velocity.push_back(film.velocity(p));
      pressure.push_back(film.pressure(p));
    }
  }
  std::ostringstream out;
  out << std::setprecision(10);
  write_grid(out, points, nu, nv);
  out << "<PointData Vectors=\"velocity\">\n<DataArray type=\"Float64\" Name=\"velocity\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (const auto& v : velocity) out << v.x() << " " << v.y() << " 0\n";
  out << "</DataArray><DataArray type=\"Float64\" Name=\"pressure\" format=\"ascii\">\n";
  for (const double p : pressure) out << p << "\n";
  out << "</DataArray></PointData>\n</Piece></UnstructuredGrid></VTKFile>\n";
  write_file_atomically(path, out.str());
}

void write_tool_vtu(const std::string& path, const spline::SplineCurve& tool) {
  constexpr int kPoints = 2000;
  std::ostringstream out;
  out << std::setprecision(10);
  out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      << "<UnstructuredGrid><Piece NumberOfPoints=\"" << kPoints + 1 << "\" NumberOfCells=\"1\">\n"
      << "<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (int k = 0; k <= kPoints; ++k) {
    const Eigen::Vector2d x = tool.point(tool.basis().lo() + (tool.basis().hi() - tool.basis().lo()) * k / kPoints);
    out << x.x() << " " << x.y() << " 0\n";
  }
  out << "</DataArray></Points>\n<Cells><DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">\n";
  for (int k = 0; k <= kPoints; ++k) out << k << "\n";
  out << "</DataArray><DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">\n" << kPoints + 1
      << "\n</DataArray><DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n" << kVtkPolyLine
      << "\n</DataArray></Cells>\n</Piece></UnstructuredGrid></VTKFile>\n";
  write_file_atomically(path, out.str());
}

void write_contact_csv(const std::string& path, const contact::ContactState& contact) {
  std::ostringstream out;
  out << std::setprecision(12);
  out << "reference_x_m,weight_m,x_m,y_m,gap_m,pressure_pa,shear_pa,normal_x,normal_y,wetted\n";
  for (size_t q = 0; q < contact.point_x.size(); ++q) {
    const Eigen::Vector2d& x = contact.point_position[q];
    const Eigen::Vector2d& n = contact.point_normal[q];
    out << contact.point_x[q] << "," << contact.point_weight[q] << "," << x.x() << "," << x.y() << ",";
    if (contact.point_gap[q]) out << *contact.point_gap[q];  // empty: too far from the tool to be searched
    out << "," << contact.point_pressure[q] << "," << contact.point_shear[q] << "," << n.x() << "," << n.y() << ","
        << (contact.point_wetted[q] != 0 ? 1 : 0) << "\n";
  }
  write_file_atomically(path, out.str());
}

}  // namespace mufric::run
