#pragma once
// ParaView output (VTK XML unstructured grids, ASCII): the deformed chip sampled on a grid inside
// every element with displacement, contact pressure, plastic strain and temperature; the lubricant
// film with velocity and pressure; the tool as a polyline; and the contact's surface points as CSV.
// Files are written to a temporary name and renamed: a crash never leaves half a file.
#include <string>

#include "micro/contact/mortar_contact.hpp"
#include "micro/fluid/navier_stokes.hpp"

namespace mufric::run {

void write_chip_vtu(const std::string& path, const solid::SolidProblem& problem, const Eigen::VectorXd& u,
                    const contact::ContactState& contact);
// The lubricant film on its current mesh: velocity and pressure.
void write_film_vtu(const std::string& path, const fluid::NavierStokes& film);
void write_tool_vtu(const std::string& path, const spline::SplineCurve& tool);
// One row per surface quadrature point of the chip (SI units, named in the header): where it is,
// what it carries and along which normal, so that the resultant and its split over the contact can
// be read without rerunning. The traction on the chip is pressure · normal + shear · t with the
// tool's unit tangent t = (−normal_y, normal_x); Σ weight · traction is eq. 17's force on the chip.
void write_contact_csv(const std::string& path, const contact::ContactState& contact);

}  // namespace mufric::run
