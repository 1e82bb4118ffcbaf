#include <bodyfit/surface_fem.hpp>

#include <bodyfit/error.hpp>
#include <bodyfit/geometry.hpp>

#include <Eigen/SparseCholesky>
#include <fmt/format.h>

#include <array>
#include <stdexcept>
#include <utility>

namespace bodyfit {

namespace {

using Triplets = std::vector<Eigen::Triplet<double>>;

Eigen::SparseMatrix<double> assemble(const SurfaceMesh& mesh, const Triplets& triplets) {
  Eigen::SparseMatrix<double> matrix(static_cast<Eigen::Index>(mesh.n_vertices()),
                                     static_cast<Eigen::Index>(mesh.n_vertices()));
  matrix.setFromTriplets(triplets.begin(), triplets.end());  // duplicates are summed
  return matrix;
}

}  // namespace

Eigen::SparseMatrix<double> mass_matrix(const SurfaceMesh& mesh) {
  Triplets triplets;
  triplets.reserve(9 * mesh.n_faces());
  for (auto f : mesh.faces()) {
    double area = face_area(mesh, f);
    auto vs = face_vertices(mesh, f);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        triplets.emplace_back(vs[i].idx(), vs[j].idx(), i == j ? area / 6.0 : area / 12.0);
  }
  return assemble(mesh, triplets);
}

Eigen::SparseMatrix<double> stiffness_matrix(const SurfaceMesh& mesh) {
  Triplets triplets;
  triplets.reserve(9 * mesh.n_faces());
  for (auto f : mesh.faces()) {
    auto [a, b, c] = face_points(mesh, f);
    double area = triangle_area(a, b, c);
    if (!(area > 0)) continue;  // a degenerate face carries no gradient
    auto grads = p1_basis_gradients(a, b, c);
    auto vs = face_vertices(mesh, f);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        triplets.emplace_back(vs[i].idx(), vs[j].idx(), area * OpenMesh::dot(grads[i], grads[j]));
  }
  return assemble(mesh, triplets);
}

std::vector<double> lumped_mass(const SurfaceMesh& mesh) {
  std::vector<double> mass(mesh.n_vertices(), 0.0);
  for (auto f : mesh.faces()) {
    double third = face_area(mesh, f) / 3.0;
    for (auto v : face_vertices(mesh, f)) mass[v.idx()] += third;
  }
  return mass;
}

// ---- H¹ smoothing --------------------------------------------------------------------------------

struct H1Smoother::Impl {
  double length = 0;
  Eigen::SparseMatrix<double> mass;
  VectorField normals;
  // Sparse Cholesky (LDLᵀ, AMD ordering) of M + ℓ²K, absent when ℓ = 0 (the identity map).
  // Eigen's own solver, not CHOLMOD: CHOLMOD's supernodal module is GPL, and the core stays
  // under a permissive licence (see LICENSE); models that need CHOLMOD's speed link it themselves.
  using Factor = Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>>;
  std::unique_ptr<Factor> factor;

  Eigen::MatrixXd solve(const Eigen::MatrixXd& f) const {
    if (f.rows() != mass.rows())
      throw std::invalid_argument(fmt::format("H1 smoothing: field of size {} on a mesh of {} vertices", f.rows(),
                                              mass.rows()));
    Eigen::MatrixXd rhs = mass * f;
    Eigen::MatrixXd u = factor->solve(rhs);
    if (factor->info() != Eigen::Success) throw std::runtime_error("H1 smoothing: sparse Cholesky solve failed");
    return u;
  }
};

H1Smoother::H1Smoother(const SurfaceMesh& mesh, double length) {
  VectorField normals(mesh.n_vertices());
  for (auto v : mesh.vertices()) normals[v.idx()] = vertex_normal(mesh, v);
  *this = H1Smoother(mass_matrix(mesh), stiffness_matrix(mesh), length, std::move(normals));
}

H1Smoother::H1Smoother(const Eigen::SparseMatrix<double>& mass, const Eigen::SparseMatrix<double>& stiffness,
                       double length, VectorField normals)
    : impl_(std::make_unique<Impl>()) {
  if (!(length >= 0)) throw InputError(fmt::format("H1 smoothing: the length must be >= 0 (got {})", length));
  impl_->length = length;
  impl_->normals = std::move(normals);
  if (length == 0) return;
  impl_->mass = mass;
  Eigen::SparseMatrix<double> system = mass + (length * length) * stiffness;
  impl_->factor = std::make_unique<Impl::Factor>();
  impl_->factor->compute(system);
  if (impl_->factor->info() != Eigen::Success)
    throw InputError("H1 smoothing: M + l^2 K is not positive definite (isolated vertex or degenerate mesh)");
}

H1Smoother::~H1Smoother() = default;
H1Smoother::H1Smoother(H1Smoother&&) noexcept = default;
H1Smoother& H1Smoother::operator=(H1Smoother&&) noexcept = default;

double H1Smoother::length() const { return impl_->length; }

ScalarField H1Smoother::smooth(const ScalarField& f) const {
  if (!impl_->factor) return f;
  Eigen::Map<const Eigen::VectorXd> rhs(f.data(), static_cast<Eigen::Index>(f.size()));
  Eigen::MatrixXd u = impl_->solve(rhs);
  return ScalarField(u.data(), u.data() + u.rows());
}

VectorField H1Smoother::smooth(const VectorField& f) const {
  VectorField result = f;
  if (impl_->factor) {
    Eigen::MatrixXd rhs(static_cast<Eigen::Index>(f.size()), 3);
    for (std::size_t i = 0; i < f.size(); ++i)
      for (int k = 0; k < 3; ++k) rhs(static_cast<Eigen::Index>(i), k) = f[i][k];
    Eigen::MatrixXd u = impl_->solve(rhs);
    for (std::size_t i = 0; i < f.size(); ++i)
      result[i] = Vec3(u(static_cast<Eigen::Index>(i), 0), u(static_cast<Eigen::Index>(i), 1),
                       u(static_cast<Eigen::Index>(i), 2));
  }
  if (impl_->normals.size() == result.size())
    for (std::size_t i = 0; i < result.size(); ++i) result[i] = project_tangent(result[i], impl_->normals[i]);
  return result;
}

ScalarField smooth_h1(const SurfaceMesh& mesh, const ScalarField& f, double length) {
  return H1Smoother(mesh, length).smooth(f);
}

VectorField smooth_h1(const SurfaceMesh& mesh, const VectorField& f, double length) {
  return H1Smoother(mesh, length).smooth(f);
}

namespace {

/// −(1/m_i) Σ_T area_T · w_T·∇φ_i at the vertices, for one vector w_T per face (`face_vector`).
template <class FaceVector>
ScalarField weak_divergence(const SurfaceMesh& mesh, FaceVector&& face_vector) {
  ScalarField divergence(mesh.n_vertices(), 0.0);
  const std::vector<double> mass = lumped_mass(mesh);
  for (auto f : mesh.faces()) {
    std::array<VertexHandle, 3> v;
    std::array<Vec3, 3> p;
    int k = 0;
    for (auto fv : mesh.fv_range(f)) v[k] = fv, p[k] = mesh.point(fv), ++k;
    const Vec3 cross = OpenMesh::cross(p[1] - p[0], p[2] - p[0]);  // |cross| = 2 area
    const double twice_area = cross.norm();
    if (!(twice_area > 0)) continue;
    const Vec3 normal = cross / twice_area;
    const Vec3 w = face_vector(f, v);
    for (int i = 0; i < 3; ++i) {
      // ∇φ_i = n × (the edge opposite i, oriented) / (2 area).
      const Vec3 gradient = OpenMesh::cross(normal, p[(i + 2) % 3] - p[(i + 1) % 3]) / twice_area;
      divergence[v[i].idx()] -= 0.5 * twice_area * OpenMesh::dot(w, gradient);
    }
  }
  for (std::size_t i = 0; i < divergence.size(); ++i)
    divergence[i] = mass[i] > 0 ? divergence[i] / mass[i] : 0.0;
  return divergence;
}

}  // namespace

ScalarField surface_divergence(const SurfaceMesh& mesh, const VectorField& field) {
  if (field.size() != mesh.n_vertices())
    throw InputError(fmt::format("surface_divergence: {} vectors for {} vertices", field.size(), mesh.n_vertices()));
  // V linear on each face: ∫_T V·∇φ_i = area · V̄·∇φ_i with V̄ the mean of its corners.
  return weak_divergence(mesh, [&](FaceHandle, const std::array<VertexHandle, 3>& v) {
    return (field[v[0].idx()] + field[v[1].idx()] + field[v[2].idx()]) / 3.0;
  });
}

ScalarField level_set_curvature(const SurfaceMesh& mesh, const ScalarField& d) {
  if (d.size() != mesh.n_vertices())
    throw InputError(fmt::format("level_set_curvature: {} values for {} vertices", d.size(), mesh.n_vertices()));
  const VectorField gradients = face_gradients(mesh, d);
  return weak_divergence(mesh, [&](FaceHandle f, const std::array<VertexHandle, 3>&) {
    const Vec3& g = gradients[f.idx()];
    const double length = g.norm();
    return length > 0 ? g / length : Vec3(0, 0, 0);
  });
}

}  // namespace bodyfit
