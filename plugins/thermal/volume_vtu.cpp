#include "volume_vtu.hpp"

#include <bodyfit/atomic_file.hpp>

#include <fmt/format.h>

namespace bodyfit::thermal {

void write_volume_vtu(const VolumeMesh& mesh, const std::vector<std::pair<std::string, const Eigen::VectorXd*>>& fields,
                      const std::filesystem::path& file) {
  write_atomically(file, [&](std::ostream& out) {
    out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
        << "<UnstructuredGrid>\n"
        << fmt::format("<Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n", mesh.n_vertices(), mesh.n_tets());
    out << "<PointData>\n";
    for (const auto& [name, values] : fields) {
      out << fmt::format("<DataArray type=\"Float64\" Name=\"{}\" format=\"ascii\">\n", name);
      for (Eigen::Index i = 0; i < values->size(); ++i) out << fmt::format("{:.9g}\n", (*values)[i]);
      out << "</DataArray>\n";
    }
    out << "</PointData>\n<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
    for (const Vec3& p : mesh.points) out << fmt::format("{:.17g} {:.17g} {:.17g}\n", p[0], p[1], p[2]);
    out << "</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">\n";
    for (const auto& t : mesh.tets) out << fmt::format("{} {} {} {}\n", t[0], t[1], t[2], t[3]);
    out << "</DataArray>\n<DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">\n";
    for (std::size_t i = 1; i <= mesh.n_tets(); ++i) out << 4 * i << "\n";
    out << "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
    for (std::size_t i = 0; i < mesh.n_tets(); ++i) out << "10\n";  // VTK_TETRA
    out << "</DataArray>\n</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
  });
}

}  // namespace bodyfit::thermal
