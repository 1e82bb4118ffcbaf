#pragma once
// SurfaceMesh: the one in-memory mesh every stage of bodyfit works on.
//
// An OpenMesh triangle mesh with double-precision points and the standard status flags (needed for
// deletion, collapse and garbage collection), plus the named properties that carry the region, the
// interface, the level set and the meshing constraints. They follow MMG's conventions so that Medit
// files interoperate:
//
//   f:region    int   triangle ref. A region mesh uses kInside (3) for G and kOutside (2) for S\G.
//   e:ref       int   Medit edge ref (0 when the edge is not listed in the file's Edges section)
//   e:interface flag  the edge lies on the interface ∂G (written with ref kInterfaceRef = 10)
//   e:ridge     flag  sharp feature edge (Medit Ridges), kept by the remesher
//   e:required  flag  never modified by the remesher (Medit RequiredEdges)
//   v:ref       int   Medit vertex ref
//   v:corner    flag  feature corner (Medit Corners), never moved or removed
//   v:required  flag  never moved or removed (Medit RequiredVertices)
//   v:phi       double the level set value (φ < 0 inside G)
//
// The properties always exist (the constructor adds them), so algorithms read them without checks,
// and they survive copies. Fields passed between algorithms are plain vectors indexed by vertex
// index (ScalarField, VectorField): a mesh must be garbage-collected before such a field is built.
#include <OpenMesh/Core/IO/MeshIO.hh>  // must precede the mesh kernel headers
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>

#include <vector>

namespace bodyfit {

struct MeshTraits : public OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3d;
  using Normal = OpenMesh::Vec3d;
  VertexAttributes(OpenMesh::Attributes::Status);
  EdgeAttributes(OpenMesh::Attributes::Status);
  FaceAttributes(OpenMesh::Attributes::Status);
  HalfedgeAttributes(OpenMesh::Attributes::PrevHalfedge);
};

using Vec3 = OpenMesh::Vec3d;
using VertexHandle = OpenMesh::VertexHandle;
using HalfedgeHandle = OpenMesh::HalfedgeHandle;
using EdgeHandle = OpenMesh::EdgeHandle;
using FaceHandle = OpenMesh::FaceHandle;

/// Region labels and interface ref, as in MMG (`mmgs -ls`).
inline constexpr int kInside = 3;
inline constexpr int kOutside = 2;
inline constexpr int kInterfaceRef = 10;

/// A scalar P1 field: one value per vertex, indexed by vertex index.
using ScalarField = std::vector<double>;
/// A vector P1 field: one vector per vertex, indexed by vertex index.
using VectorField = std::vector<Vec3>;

class SurfaceMesh : public OpenMesh::TriMesh_ArrayKernelT<MeshTraits> {
 public:
  /// Boolean tags are stored as char: OpenMesh keeps bool properties in std::vector<bool>, which
  /// cannot hand out references.
  using Flag = char;
  using Base = OpenMesh::TriMesh_ArrayKernelT<MeshTraits>;

  SurfaceMesh();
  SurfaceMesh(const SurfaceMesh&) = default;
  SurfaceMesh(SurfaceMesh&&) = default;
  SurfaceMesh& operator=(const SurfaceMesh&) = default;
  SurfaceMesh& operator=(SurfaceMesh&&) = default;

  int& region(FaceHandle f) { return property(region_, f); }
  int region(FaceHandle f) const { return property(region_, f); }
  bool inside(FaceHandle f) const { return property(region_, f) == kInside; }

  int& edge_ref(EdgeHandle e) { return property(edge_ref_, e); }
  int edge_ref(EdgeHandle e) const { return property(edge_ref_, e); }
  Flag& interface(EdgeHandle e) { return property(interface_, e); }
  bool interface(EdgeHandle e) const { return property(interface_, e); }
  Flag& ridge(EdgeHandle e) { return property(ridge_, e); }
  bool ridge(EdgeHandle e) const { return property(ridge_, e); }
  Flag& required(EdgeHandle e) { return property(required_edge_, e); }
  bool required(EdgeHandle e) const { return property(required_edge_, e); }

  int& vertex_ref(VertexHandle v) { return property(vertex_ref_, v); }
  int vertex_ref(VertexHandle v) const { return property(vertex_ref_, v); }
  Flag& corner(VertexHandle v) { return property(corner_, v); }
  bool corner(VertexHandle v) const { return property(corner_, v); }
  Flag& required(VertexHandle v) { return property(required_vertex_, v); }
  bool required(VertexHandle v) const { return property(required_vertex_, v); }
  double& phi(VertexHandle v) { return property(phi_, v); }
  double phi(VertexHandle v) const { return property(phi_, v); }

  /// The level set as a field indexed by vertex index, and back.
  ScalarField phi_field() const;
  void set_phi(const ScalarField& values);

  /// True when any face carries the inside label.
  bool has_regions() const;

 private:
  OpenMesh::FPropHandleT<int> region_;
  OpenMesh::EPropHandleT<int> edge_ref_;
  OpenMesh::EPropHandleT<Flag> interface_;
  OpenMesh::EPropHandleT<Flag> ridge_;
  OpenMesh::EPropHandleT<Flag> required_edge_;
  OpenMesh::VPropHandleT<int> vertex_ref_;
  OpenMesh::VPropHandleT<Flag> corner_;
  OpenMesh::VPropHandleT<Flag> required_vertex_;
  OpenMesh::VPropHandleT<double> phi_;
};

/// Label faces from φ at their vertices: kInside when the face's mean φ is negative, kOutside
/// otherwise; mark as interface the edges between faces of different labels. For a mesh whose
/// interface is already made of edges (every face entirely on one side), this is exact.
void label_regions_from_phi(SurfaceMesh& mesh);

/// Mark as interface exactly the edges between an inside and a non-inside face.
void update_interface_from_regions(SurfaceMesh& mesh);

}  // namespace bodyfit
