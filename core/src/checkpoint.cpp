// Checkpoint files (formats 1-4) and the canonical form of a mesh they read back.
#include <bodyfit/atomic_file.hpp>
#include <bodyfit/checkpoint.hpp>
#include <bodyfit/error.hpp>

#include <fmt/format.h>

#include <cmath>

#include <limits>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include <fcntl.h>
#include <unistd.h>

namespace bodyfit {
namespace {

// Version 1 stored the faces' corners (read back through add_face, whose cost dominated an
// iteration's remesh stage at 200k faces); version 2 stores OpenMesh's connectivity arrays as they
// are, so reading restores the exact mesh in O(n) and canonicalize() is cheap.
// Version 3 adds the Δt in force, the model's state and a checksum; version 4 the effective case.
constexpr char kMagicV1[8] = {'B', 'F', 'C', 'K', 'P', 'T', '0', '1'};
constexpr char kMagicV2[8] = {'B', 'F', 'C', 'K', 'P', 'T', '0', '2'};
constexpr char kMagicV3[8] = {'B', 'F', 'C', 'K', 'P', 'T', '0', '3'};
constexpr char kMagicV4[8] = {'B', 'F', 'C', 'K', 'P', 'T', '0', '4'};
/// The largest effective case a checkpoint holds (a case file is a few kB).
constexpr std::uint64_t kMaxCaseBytes = 1 << 24;

// Bytes per element of the format-2/3 arrays: a vertex is 3 doubles + ref + 2 flags + φ + its
// halfedge; an edge 2 × (vertex, next, face) + ref + 3 flags; a face its halfedge + region.
constexpr std::uint64_t kVertexBytes = 42, kEdgeBytes = 31, kFaceBytes = 8;
// Format 1: a vertex is 3 doubles + ref + 2 flags + φ; a face its 3 corners + region.
constexpr std::uint64_t kV1VertexBytes = 38, kV1FaceBytes = 16;

/// Checkpoint bytes written through a cursor into a buffer sized beforehand: the snapshot is one
/// sequential pass of fixed-size copies, with no growth or bounds check per value.
class Writer {
 public:
  explicit Writer(char* at) : at_(at) {}
  template <class T>
  void put(const T& value) {
    std::memcpy(at_, &value, sizeof(T));
    at_ += sizeof(T);
  }
  void put_raw(const void* bytes, std::size_t size) {
    if (size) std::memcpy(at_, bytes, size);
    at_ += size;
  }
  void put_string(const std::string& s) {
    put<std::uint64_t>(s.size());
    put_raw(s.data(), s.size());
  }
  const char* at() const { return at_; }

 private:
  char* at_;
};

/// Reading checkpoint bytes: every read is bounds-checked ("truncated checkpoint").
class Cursor {
 public:
  Cursor(const std::string& data, const std::string& name) : data_(data), name_(name) {}
  template <class T>
  T get() {
    if (data_.size() - at_ < sizeof(T)) throw InputError(fmt::format("{}: truncated checkpoint", name_));
    T value{};
    std::memcpy(&value, data_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    return value;
  }
  std::string get_string(std::uint64_t max_size) {
    const auto size = get<std::uint64_t>();
    if (size > max_size || size > remaining()) corrupt("string length out of range");
    std::string s = data_.substr(at_, size);
    at_ += size;
    return s;
  }
  std::size_t remaining() const { return data_.size() - at_; }
  /// An element index in [0, size) (or −1 when `allow_none`).
  int index(std::uint64_t size, const char* what, bool allow_none = false) {
    const auto i = get<std::int32_t>();
    if ((i < 0 && !(allow_none && i == -1)) || (i >= 0 && std::uint64_t(i) >= size))
      throw InputError(fmt::format("{}: {} index {} out of range", name_, what, i));
    return i;
  }
  [[noreturn]] void corrupt(const std::string& what) const {
    throw InputError(fmt::format("{}: corrupt checkpoint: {}", name_, what));
  }
  const std::string& name() const { return name_; }

 private:
  const std::string& data_;
  std::string name_;
  std::size_t at_ = 0;
};

void put_vertex(Writer& out, const SurfaceMesh& mesh, VertexHandle v) {
  const Vec3& p = mesh.point(v);
  out.put(p[0]), out.put(p[1]), out.put(p[2]);
  out.put<std::int32_t>(mesh.vertex_ref(v));
  out.put<char>(mesh.corner(v));
  out.put<char>(mesh.required(v));
  out.put<double>(mesh.phi(v));
}

/// The fields put_vertex wrote, into the existing vertex v.
void get_vertex(Cursor& in, SurfaceMesh& mesh, VertexHandle v) {
  const double x = in.get<double>(), y = in.get<double>(), z = in.get<double>();
  mesh.set_point(v, Vec3(x, y, z));
  mesh.vertex_ref(v) = in.get<std::int32_t>();
  mesh.corner(v) = in.get<char>();
  mesh.required(v) = in.get<char>();
  mesh.phi(v) = in.get<double>();
}

void put_edge_tags(Writer& out, const SurfaceMesh& mesh, EdgeHandle e) {
  out.put<std::int32_t>(mesh.edge_ref(e));
  out.put<char>(mesh.interface(e));
  out.put<char>(mesh.ridge(e));
  out.put<char>(mesh.required(e));
}

void get_edge_tags(Cursor& in, SurfaceMesh& mesh, EdgeHandle e) {
  mesh.edge_ref(e) = in.get<std::int32_t>();
  mesh.interface(e) = in.get<char>();
  mesh.ridge(e) = in.get<char>();
  mesh.required(e) = in.get<char>();
}

/// Version 1: vertices, faces by corners (rebuilt with add_face), tagged edges by their ends.
SurfaceMesh read_v1(Cursor& in, std::uint64_t nv, std::uint64_t nf) {
  SurfaceMesh mesh;
  mesh.reserve(nv, nv + nf + 16, nf);
  std::vector<VertexHandle> vertices(nv);
  for (std::uint64_t i = 0; i < nv; ++i) get_vertex(in, mesh, vertices[i] = mesh.new_vertex(Vec3(0, 0, 0)));
  for (std::uint64_t i = 0; i < nf; ++i) {
    const int a = in.index(nv, "vertex"), b = in.index(nv, "vertex"), c = in.index(nv, "vertex");
    // OpenMesh asserts (abort) on a face that uses a vertex twice (found by fuzz_checkpoint).
    if (a == b || b == c || a == c) in.corrupt(fmt::format("face {} uses a vertex twice", i));
    const auto f = mesh.add_face(vertices[a], vertices[b], vertices[c]);
    if (!f.is_valid()) throw InputError(fmt::format("{}: face {} is not manifold", in.name(), i));
    mesh.region(f) = in.get<std::int32_t>();
  }
  const auto tagged = in.get<std::uint64_t>();
  for (std::uint64_t i = 0; i < tagged; ++i) {
    const int a = in.index(nv, "vertex"), b = in.index(nv, "vertex");
    const auto h = mesh.find_halfedge(vertices[a], vertices[b]);
    if (!h.is_valid()) throw InputError(fmt::format("{}: tagged edge {} is not in the mesh", in.name(), i));
    get_edge_tags(in, mesh, mesh.edge_handle(h));
  }
  return mesh;
}

/// Version 2: OpenMesh's connectivity arrays restored as they were written, then checked (each
/// face a 3-cycle of its own halfedges, consecutive halfedges meeting at a vertex, each vertex's
/// halfedge leaving it), so a corrupt file is an error rather than a broken mesh.
SurfaceMesh read_v2(Cursor& in, std::uint64_t nv, std::uint64_t ne, std::uint64_t nf) {
  SurfaceMesh mesh;
  // All arrays at once (one resize per property, not one per element), then filled in place.
  mesh.resize(nv, ne, nf);
  const std::uint64_t nh = 2 * ne;
  for (std::uint64_t i = 0; i < nv; ++i) {
    const VertexHandle v{int(i)};
    get_vertex(in, mesh, v);
    mesh.set_halfedge_handle(v, HalfedgeHandle(in.index(nh, "halfedge", true)));
  }
  for (std::uint64_t e = 0; e < ne; ++e) {
    for (int side = 0; side < 2; ++side) {
      const HalfedgeHandle h{int(2 * e + side)};
      mesh.set_vertex_handle(h, VertexHandle(in.index(nv, "vertex")));
      mesh.set_next_halfedge_handle(h, HalfedgeHandle(in.index(nh, "halfedge")));
      mesh.set_face_handle(h, FaceHandle(in.index(nf, "face", true)));
    }
    get_edge_tags(in, mesh, EdgeHandle(int(e)));
  }
  for (std::uint64_t f = 0; f < nf; ++f) {
    const FaceHandle fh{int(f)};
    mesh.set_halfedge_handle(fh, HalfedgeHandle(in.index(nh, "halfedge")));
    mesh.region(fh) = in.get<std::int32_t>();
  }
  for (std::uint64_t h = 0; h < nh; ++h) {
    const HalfedgeHandle hh{int(h)};
    if (mesh.to_vertex_handle(hh) != mesh.from_vertex_handle(mesh.next_halfedge_handle(hh)))
      in.corrupt(fmt::format("halfedge {} and its next do not meet", h));
  }
  for (std::uint64_t f = 0; f < nf; ++f) {
    HalfedgeHandle h = mesh.halfedge_handle(FaceHandle(int(f)));
    for (int k = 0; k < 3; ++k, h = mesh.next_halfedge_handle(h))
      if (mesh.face_handle(h).idx() != int(f)) in.corrupt(fmt::format("face {} is not a triangle of its halfedges", f));
    if (h != mesh.halfedge_handle(FaceHandle(int(f)))) in.corrupt(fmt::format("face {} is not a triangle", f));
  }
  for (std::uint64_t v = 0; v < nv; ++v) {
    const HalfedgeHandle h = mesh.halfedge_handle(VertexHandle(int(v)));
    if (h.is_valid() && mesh.from_vertex_handle(h).idx() != int(v))
      in.corrupt(fmt::format("vertex {}'s halfedge does not leave it", v));
  }
  return mesh;
}

/// Whether elements are marked deleted (the arrays would then not be the mesh).
bool has_deleted(const SurfaceMesh& mesh) {
  for (auto v : mesh.all_vertices())
    if (mesh.status(v).deleted()) return true;
  for (auto e : mesh.all_edges())
    if (mesh.status(e).deleted()) return true;
  for (auto f : mesh.all_faces())
    if (mesh.status(f).deleted()) return true;
  return false;
}

/// A 64-bit checksum of a byte string, 8 bytes per round (a damaged or truncated file is caught
/// before its counts are trusted; not a cryptographic hash).
std::uint64_t checksum(const char* data, std::size_t size) {
  std::uint64_t h = 0x243F6A8885A308D3ull ^ size;
  auto mix = [&h](std::uint64_t word) {
    h ^= word;
    h *= 0x9E3779B97F4A7C15ull;
    h ^= h >> 29;
  };
  std::size_t at = 0;
  for (; at + 8 <= size; at += 8) {
    std::uint64_t word;
    std::memcpy(&word, data + at, 8);
    mix(word);
  }
  std::uint64_t tail = 0;
  std::memcpy(&tail, data + at, size - at);
  mix(tail);
  return h;
}

enum class EntryType : std::uint8_t { Numbers = 0, Integers = 1, Bytes = 2 };

/// The size of what put_model_state writes.
std::size_t model_state_size(const ModelState& state) {
  std::size_t size = 4 + 8;
  for (const auto& [key, value] : state.values()) {
    size += 8 + key.size() + 1;
    if (const auto* numbers = std::get_if<std::vector<double>>(&value)) size += 8 + numbers->size() * sizeof(double);
    else if (const auto* integers = std::get_if<std::vector<std::int64_t>>(&value))
      size += 8 + integers->size() * sizeof(std::int64_t);
    else size += 8 + std::get<std::string>(value).size();
  }
  return size;
}

void put_model_state(Writer& out, const ModelState& state) {
  out.put<std::uint32_t>(state.version);
  out.put<std::uint64_t>(state.values().size());
  for (const auto& [key, value] : state.values()) {
    out.put_string(key);
    if (const auto* numbers = std::get_if<std::vector<double>>(&value)) {
      out.put(EntryType::Numbers);
      out.put<std::uint64_t>(numbers->size());
      out.put_raw(reinterpret_cast<const char*>(numbers->data()), numbers->size() * sizeof(double));
    } else if (const auto* integers = std::get_if<std::vector<std::int64_t>>(&value)) {
      out.put(EntryType::Integers);
      out.put<std::uint64_t>(integers->size());
      out.put_raw(reinterpret_cast<const char*>(integers->data()), integers->size() * sizeof(std::int64_t));
    } else {
      out.put(EntryType::Bytes);
      out.put_string(std::get<std::string>(value));
    }
  }
}

template <class T>
std::vector<T> get_array(Cursor& in) {
  const auto count = in.get<std::uint64_t>();
  if (count > in.remaining() / sizeof(T)) in.corrupt("model state array longer than the file");
  std::vector<T> values(count);
  for (auto& v : values) v = in.get<T>();
  return values;
}

ModelState get_model_state(Cursor& in) {
  ModelState state;
  state.version = in.get<std::uint32_t>();
  const auto entries = in.get<std::uint64_t>();
  if (entries > in.remaining()) in.corrupt("model state entry count out of range");
  for (std::uint64_t i = 0; i < entries; ++i) {
    std::string key = in.get_string(4096);
    switch (in.get<EntryType>()) {
      case EntryType::Numbers: state.set(key, get_array<double>(in)); break;
      case EntryType::Integers: state.set(key, get_array<std::int64_t>(in)); break;
      case EntryType::Bytes: state.set(key, in.get_string(in.remaining())); break;
      default: in.corrupt(fmt::format("model state entry '{}' has an unknown type", key));
    }
  }
  return state;
}

/// Fsync a file or directory so that a power loss after the rename keeps it (best effort for the
/// directory: some file systems refuse to sync one).
void sync_path(const std::filesystem::path& path, bool directory) {
  const int fd = ::open(path.c_str(), O_RDONLY | (directory ? O_DIRECTORY : 0));
  if (fd < 0) {
    if (directory) return;
    throw file_error(path, fmt::format("cannot open to sync ({})", std::strerror(errno)));
  }
  const int failed = ::fsync(fd);
  const int error = errno;
  ::close(fd);
  if (failed && !directory) throw file_error(path, fmt::format("fsync failed ({})", std::strerror(error)));
}

Checkpoint decode_checkpoint(const std::string& data, const std::string& name) {
  Cursor in(data, name);
  char magic[8];
  for (char& c : magic) c = in.get<char>();
  Checkpoint c;
  if (std::equal(magic, magic + 8, kMagicV1)) c.format = 1;
  else if (std::equal(magic, magic + 8, kMagicV2)) c.format = 2;
  else if (std::equal(magic, magic + 8, kMagicV3)) c.format = 3;
  else if (std::equal(magic, magic + 8, kMagicV4)) c.format = 4;
  else throw InputError(fmt::format("{}: not a bodyfit checkpoint", name));
  if (c.format >= 3) {  // the checksum first: nothing of a damaged file is trusted
    std::uint64_t stored = 0;
    if (data.size() >= 16) std::memcpy(&stored, data.data() + data.size() - 8, 8);
    if (data.size() < 16 || stored != checksum(data.data(), data.size() - 8))
      throw InputError(fmt::format("{}: corrupt checkpoint: checksum mismatch (the file is damaged or truncated)", name));
  }
  const auto iteration = in.get<std::int64_t>();
  c.run.time = in.get<double>();
  if (c.format >= 3) c.run.dt = in.get<double>();
  // An intact checksum over content no run can have written (another program's, a hand-made file)
  // is refused here, not met as an overflow or a NaN time steps later.
  if (iteration < 0 || iteration >= std::numeric_limits<int>::max() - 1)
    throw InputError(fmt::format("{}: corrupt checkpoint: iteration {} (expected 0 to {})", name, iteration,
                                 std::numeric_limits<int>::max() - 2));
  if (!std::isfinite(c.run.time) || !std::isfinite(c.run.dt) || c.run.dt < 0)
    throw InputError(fmt::format("{}: corrupt checkpoint: time {} and step {} (expected finite, the step ≥ 0)", name,
                                 c.run.time, c.run.dt));
  c.run.iteration = int(iteration);
  const auto nv = in.get<std::uint64_t>();
  const auto ne = c.format >= 2 ? in.get<std::uint64_t>() : 0;
  const auto nf = in.get<std::uint64_t>();
  // Counts against the length before anything is allocated (format 1 too: a 41-byte file once
  // reserved 2^31 vertices, found by fuzz_checkpoint).
  const std::uint64_t needed = c.format >= 2 ? kVertexBytes * nv + kEdgeBytes * ne + kFaceBytes * nf
                                             : kV1VertexBytes * nv + kV1FaceBytes * nf;
  if (nv > (1ull << 31) || ne > (1ull << 30) || nf > (1ull << 31) || needed > in.remaining())
    throw InputError(fmt::format("{}: corrupt checkpoint sizes ({} vertices, {} edges, {} faces in {} bytes)", name,
                                 nv, ne, nf, data.size()));
  c.mesh = c.format >= 2 ? read_v2(in, nv, ne, nf) : read_v1(in, nv, nf);
  if (c.format >= 3 && in.get<std::uint8_t>() == 1) c.model = get_model_state(in);
  if (c.format >= 4) c.case_text = in.get_string(kMaxCaseBytes);
  return c;
}

}  // namespace

void CheckpointSnapshot::seal() {
  if (size_ < 8) return;
  const std::uint64_t sum = checksum(data_.get(), size_ - 8);
  std::memcpy(data_.get() + size_ - 8, &sum, 8);
}

void take_snapshot(CheckpointSnapshot& into, const SurfaceMesh& mesh, const RunState& run, const ModelState* model,
                   std::string_view case_text) {
  if (has_deleted(mesh)) throw std::logic_error("take_snapshot: the mesh must be garbage-collected");
  if (case_text.size() > kMaxCaseBytes) throw std::logic_error("take_snapshot: the case is too long to record");
  const std::size_t nv = mesh.n_vertices(), ne = mesh.n_edges(), nf = mesh.n_faces();
  const std::size_t size = 56 + kVertexBytes * nv + kEdgeBytes * ne + kFaceBytes * nf + 1 +
                           (model ? model_state_size(*model) : 0) + 8 + case_text.size() + 8;
  if (into.capacity_ < size) {
    into.data_.reset();  // free the old buffer before taking the larger one
    into.data_ = std::make_unique_for_overwrite<char[]>(size);
    into.capacity_ = size;
  }
  into.size_ = size;
  into.iteration_ = run.iteration;
  Writer out(into.data_.get());
  out.put_raw(kMagicV4, sizeof kMagicV4);
  out.put<std::int64_t>(run.iteration);
  out.put<double>(run.time);
  out.put<double>(run.dt);
  out.put<std::uint64_t>(nv);
  out.put<std::uint64_t>(ne);
  out.put<std::uint64_t>(nf);
  // By index: the mesh has no deleted element, so indices are the iteration order.
  for (std::size_t i = 0; i < nv; ++i) {
    const VertexHandle v{int(i)};
    put_vertex(out, mesh, v);
    out.put<std::int32_t>(mesh.halfedge_handle(v).idx());
  }
  for (std::size_t i = 0; i < ne; ++i) {
    for (int side = 0; side < 2; ++side) {
      const HalfedgeHandle h{int(2 * i) + side};
      out.put<std::int32_t>(mesh.to_vertex_handle(h).idx());
      out.put<std::int32_t>(mesh.next_halfedge_handle(h).idx());
      out.put<std::int32_t>(mesh.face_handle(h).idx());
    }
    put_edge_tags(out, mesh, EdgeHandle(int(i)));
  }
  for (std::size_t i = 0; i < nf; ++i) {
    const FaceHandle f{int(i)};
    out.put<std::int32_t>(mesh.halfedge_handle(f).idx());
    out.put<std::int32_t>(mesh.region(f));
  }
  out.put<std::uint8_t>(model ? 1 : 0);
  if (model) put_model_state(out, *model);
  out.put<std::uint64_t>(case_text.size());
  out.put_raw(case_text.data(), case_text.size());
  out.put<std::uint64_t>(0);  // the checksum, filled in by seal()
  if (out.at() != into.data_.get() + size) throw std::logic_error("take_snapshot: size mismatch");
}

void save_checkpoint(const std::filesystem::path& file, CheckpointSnapshot& snapshot) {
  snapshot.seal();
  const std::string_view bytes = snapshot.bytes();
  write_atomically(file, [&](std::ostream& out) { out.write(bytes.data(), std::streamsize(bytes.size())); });
  // After the rename (write_atomically owns the temporary): the new file, then its directory entry.
  sync_path(file, false);
  sync_path(file.has_parent_path() ? file.parent_path() : std::filesystem::path("."), true);
}

void write_checkpoint(std::ostream& out, const SurfaceMesh& mesh, const RunState& run, const ModelState* model) {
  CheckpointSnapshot snapshot;
  take_snapshot(snapshot, mesh, run, model);
  snapshot.seal();
  out.write(snapshot.bytes().data(), std::streamsize(snapshot.bytes().size()));
}

Checkpoint read_checkpoint(std::istream& in, const std::string& name) {
  const std::string data{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  return decode_checkpoint(data, name);
}

void save_checkpoint(const std::filesystem::path& file, const SurfaceMesh& mesh, const RunState& run,
                     const ModelState* model) {
  CheckpointSnapshot snapshot;
  take_snapshot(snapshot, mesh, run, model);
  save_checkpoint(file, snapshot);
}

Checkpoint load_checkpoint(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw file_error(file, "cannot open checkpoint");
  return read_checkpoint(in, file.string());
}

void canonicalize(SurfaceMesh& mesh) {
  // A checkpoint stores OpenMesh's arrays as they are (format 2/3), so what a resumed run reads
  // back differs from the live mesh only in what is not stored: deleted elements and status bits.
  // (This replaced an encode + decode round trip of the whole mesh every iteration.)
  if (has_deleted(mesh)) mesh.garbage_collection();
  for (auto v : mesh.vertices()) mesh.status(v).set_bits(0);
  for (auto e : mesh.edges()) mesh.status(e).set_bits(0);
  for (auto f : mesh.faces()) mesh.status(f).set_bits(0);
}

}  // namespace bodyfit
