#pragma once
// The Advector of a step's CFL sub-steps in a narrow band: built on the faces around the band and
// as far as the step's characteristics are expected to reach, built again further out when the
// band comes near its edge. Its traces are the whole mesh's Advector's, bit for bit (Advector's
// constructor on faces), at a cost that follows the front instead of the mesh.
#include <bodyfit/advection.hpp>
#include <bodyfit/mesh.hpp>

#include <optional>
#include <span>
#include <vector>

namespace bodyfit {

/// The faces with a corner among `vertices`, each once, in index order.
std::vector<int> faces_around(const SurfaceMesh& mesh, std::span<const int> vertices);

class BandAdvector {
 public:
  explicit BandAdvector(const SurfaceMesh& mesh) : mesh_(mesh) {}

  /// An Advector whose faces hold every face around `known` (what a band call reads); built, or
  /// built again, on the faces within `rings` rings of `known` when the last one does not.
  Advector& covering(std::span<const int> known, int rings);
  /// How many times an Advector was built.
  int builds() const { return builds_; }

 private:
  bool covers(std::span<const int> known) const;

  const SurfaceMesh& mesh_;
  std::optional<Advector> advector_;
  std::vector<char> built_;  ///< per face: in advector_
  int builds_ = 0;
};

}  // namespace bodyfit
