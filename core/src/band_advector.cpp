// The sub-steps' Advector on the faces around a moving band.
#include <bodyfit/band_advector.hpp>

#include <algorithm>

namespace bodyfit {

std::vector<int> faces_around(const SurfaceMesh& mesh, std::span<const int> vertices) {
  std::vector<char> seen(mesh.n_faces(), 0);
  std::vector<int> faces;
  for (int v : vertices)
    for (auto f : mesh.vf_range(VertexHandle(v)))
      if (!seen[f.idx()]) seen[f.idx()] = 1, faces.push_back(f.idx());
  std::sort(faces.begin(), faces.end());
  return faces;
}

bool BandAdvector::covers(std::span<const int> known) const {
  if (!advector_) return false;
  for (int v : known)
    for (auto f : mesh_.vf_range(VertexHandle(v)))
      if (!built_[std::size_t(f.idx())]) return false;
  return true;
}

Advector& BandAdvector::covering(std::span<const int> known, int rings) {
  if (covers(known)) return *advector_;
  // The vertices within `rings` rings of `known`, found ring by ring.
  std::vector<char> seen(mesh_.n_vertices(), 0);
  std::vector<int> vertices(known.begin(), known.end());
  for (int v : vertices) seen[std::size_t(v)] = 1;
  for (std::size_t begin = 0, ring = 0; ring < std::size_t(std::max(rings, 0)); ++ring) {
    const std::size_t end = vertices.size();
    for (std::size_t i = begin; i < end; ++i)
      for (auto w : mesh_.vv_range(VertexHandle(vertices[i])))
        if (!seen[std::size_t(w.idx())]) {
          seen[std::size_t(w.idx())] = 1;
          vertices.push_back(w.idx());
        }
    begin = end;
  }
  const std::vector<int> faces = faces_around(mesh_, vertices);
  built_.assign(mesh_.n_faces(), 0);
  for (int f : faces) built_[std::size_t(f)] = 1;
  advector_.reset();  // its memory first
  advector_.emplace(mesh_, faces);
  ++builds_;
  return *advector_;
}

}  // namespace bodyfit
