#pragma once
// The volume mesh with the temperature inside, as a VTK XML UnstructuredGrid of tetrahedra (ParaView:
// clip or slice it to see u inside the part).
#include "volume_mesh.hpp"

#include <Eigen/Core>

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace bodyfit::thermal {

/// Point fields (one value per volume vertex) written with the tetrahedra; atomic (temporary + rename).
void write_volume_vtu(const VolumeMesh& mesh, const std::vector<std::pair<std::string, const Eigen::VectorXd*>>& fields,
                      const std::filesystem::path& file);

}  // namespace bodyfit::thermal
