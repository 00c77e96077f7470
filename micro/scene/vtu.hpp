#pragma once
// ParaView output (VTK XML unstructured grids, ASCII): the deformed chip sampled on a grid inside
// every element with displacement, contact pressure, plastic strain and temperature; the lubricant
// film with velocity and pressure; the tool as a polyline. Files are written to a temporary name and renamed: a crash never leaves half a file.
#include <string>

#include "micro/contact/mortar_contact.hpp"
#include "micro/fluid/navier_stokes.hpp"

namespace mufric::scene {

void write_chip_vtu(const std::string& path, const solid::SolidProblem& problem, const Eigen::VectorXd& u,
                    const contact::ContactState& contact);
// The lubricant film on its current mesh: velocity and pressure.
void write_film_vtu(const std::string& path, const fluid::NavierStokes& film);
void write_tool_vtu(const std::string& path, const spline::SplineCurve& tool);

}  // namespace mufric::scene
