#include "volume_mesh.hpp"

#include "surface_check.hpp"

#include <bodyfit/error.hpp>
#include <bodyfit/geometry.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <new>
#include <numbers>
#include <stdexcept>
#include <string>

#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

// TetGen's header defines REAL and a few other macros: it stays in this file.
#include <tetgen.h>

namespace bodyfit::thermal {

namespace {

/// The arrays of TetGen's output that the volume mesh is made of (zero-based).
struct TetgenOutput {
  std::vector<double> points;  // 3 per point
  std::vector<int> tets;       // 4 per tetrahedron
  std::vector<int> faces;      // 3 per boundary face
  std::vector<int> markers;    // 1 per boundary face: the facet marker (surface face + 1)
};

/// What TetGen's terminatetetgen(code) means (tetgen.h, its non-library branch prints the same).
std::string tetgen_error(int code) {
  switch (code) {
    case 1: return "TetGen ran out of memory";
    case 2: return "TetGen hit an internal error";
    case 3: return "TetGen found a self-intersection of the surface";
    case 4: return "TetGen found an input feature smaller than its tolerance (nearly touching parts of the surface)";
    case 5: return "TetGen found two input faces too close to each other";
    case 10: return "TetGen rejected the input";
    default: return fmt::format("TetGen stopped with code {}", code);
  }
}

/// TetGen's switches. 'p' PLC, 'Y' no Steiner point on the boundary, 'q' quality, 'a' volume bound,
/// 'z' zero-based indices, 'Q' quiet. Numbers in full precision ('a' accepts exponents, 'q' does not).
std::string switches(const TetrahedralizeOptions& options) {
  if (!(options.radius_edge_ratio >= 1.0) || !std::isfinite(options.radius_edge_ratio))
    throw InputError(fmt::format("tetrahedralize: radius_edge_ratio = {} (expected ≥ 1; TetGen may not terminate "
                                 "below about 1.1)",
                                 options.radius_edge_ratio));
  if (!(options.max_volume >= 0) || !std::isfinite(options.max_volume))
    throw InputError(fmt::format("tetrahedralize: max_volume = {} (expected ≥ 0, 0 = no bound)", options.max_volume));
  std::string s = fmt::format("pYzQq{:.6f}", options.radius_edge_ratio);
  if (options.max_volume > 0) s += fmt::format("a{:.17g}", options.max_volume);
  return s;
}

template <class T>
void copy_out(std::vector<T>& to, const T* from, long count) {
  to.clear();
  if (from != nullptr && count > 0) to.assign(from, from + count);
}

/// Run TetGen in this process. Its errors with no mesh allocated yet (bad switches) arrive as an int;
/// the others do not arrive at all (see TetrahedralizeOptions::isolate).
TetgenOutput run_here(tetgenio& in, const std::string& command) {
  tetgenio out;  // its destructor frees every list
  std::vector<char> writable(command.begin(), command.end());
  writable.push_back('\0');
  try {
    ::tetrahedralize(writable.data(), &in, &out);
  } catch (int code) {
    throw InputError(fmt::format("tetrahedralize: {} (code {}, switches -{})", tetgen_error(code), code, command));
  } catch (const std::bad_alloc&) {
    throw InputError(fmt::format("tetrahedralize: out of memory (switches -{})", command));
  }
  if (out.numberofcorners != 4) throw std::logic_error("tetrahedralize: TetGen returned non-linear tetrahedra");
  TetgenOutput result;
  copy_out(result.points, out.pointlist, 3L * out.numberofpoints);
  copy_out(result.tets, out.tetrahedronlist, 4L * out.numberoftetrahedra);
  copy_out(result.faces, out.trifacelist, 3L * out.numberoftrifaces);
  copy_out(result.markers, out.trifacemarkerlist, long(out.numberoftrifaces));
  return result;
}

// ---- the isolated run: a child process, the mesh through a pipe ----------------------------------

bool write_all(int fd, const void* data, std::size_t size) {
  const char* p = static_cast<const char*>(data);
  while (size > 0) {
    ssize_t n = ::write(fd, p, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    p += n, size -= std::size_t(n);
  }
  return true;
}

template <class T>
bool write_array(int fd, const std::vector<T>& a) {
  std::uint64_t n = a.size();
  return write_all(fd, &n, sizeof n) && write_all(fd, a.data(), n * sizeof(T));
}

template <class T>
bool read_array(const std::string& buffer, std::size_t& at, std::vector<T>& a) {
  std::uint64_t n = 0;
  if (buffer.size() - at < sizeof n) return false;
  std::memcpy(&n, buffer.data() + at, sizeof n);
  at += sizeof n;
  if ((buffer.size() - at) / sizeof(T) < n) return false;
  a.resize(n);
  std::memcpy(a.data(), buffer.data() + at, n * sizeof(T));
  at += n * sizeof(T);
  return true;
}

/// The last `count` non-empty lines of `text`, trimmed, joined by " / ".
std::string last_lines(const std::string& text, std::size_t count) {
  std::vector<std::string> lines;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = std::min(text.find('\n', start), text.size());
    std::string line = text.substr(start, end - start);
    std::size_t first = line.find_first_not_of(" \t\r");
    if (first != std::string::npos) lines.push_back(line.substr(first, line.find_last_not_of(" \t\r") - first + 1));
    start = end + 1;
  }
  std::string joined;
  for (std::size_t i = lines.size() > count ? lines.size() - count : 0; i < lines.size(); ++i)
    joined += (joined.empty() ? "" : " / ") + lines[i];
  return joined;
}

/// Read both pipes until both are closed (the child blocks when one is full).
void drain(int data_fd, int text_fd, std::string& data, std::string& text) {
  pollfd fds[2] = {{data_fd, POLLIN, 0}, {text_fd, POLLIN, 0}};
  std::string* sinks[2] = {&data, &text};
  int open = 2;
  std::vector<char> chunk(1 << 16);
  while (open > 0) {
    if (::poll(fds, 2, -1) < 0) {
      if (errno == EINTR) continue;
      break;
    }
    for (int k = 0; k < 2; ++k) {
      if (fds[k].fd < 0 || !(fds[k].revents & (POLLIN | POLLHUP | POLLERR))) continue;
      ssize_t n = ::read(fds[k].fd, chunk.data(), chunk.size());
      if (n < 0 && errno == EINTR) continue;
      if (n > 0) {
        sinks[k]->append(chunk.data(), std::size_t(n));
      } else {
        ::close(fds[k].fd);
        fds[k].fd = -1;
        --open;
      }
    }
  }
  for (const auto& fd : fds)
    if (fd.fd >= 0) ::close(fd.fd);
}

TetgenOutput run_isolated(tetgenio& in, const std::string& command) {
  int data[2], text[2];
  if (::pipe(data) != 0) throw InputError(fmt::format("tetrahedralize: pipe failed: {}", std::strerror(errno)));
  if (::pipe(text) != 0) {
    ::close(data[0]), ::close(data[1]);
    throw InputError(fmt::format("tetrahedralize: pipe failed: {}", std::strerror(errno)));
  }
  std::fflush(stdout);  // nothing buffered may be written twice
  pid_t pid = ::fork();
  if (pid < 0) {
    for (int fd : {data[0], data[1], text[0], text[1]}) ::close(fd);
    throw InputError(fmt::format("tetrahedralize: fork failed: {}", std::strerror(errno)));
  }
  if (pid == 0) {
    // The child. TetGen's printf output goes to the text pipe, unbuffered so that a crash loses
    // nothing; a status (0, or 1 with our message in the text) and the arrays go to the data pipe.
    // _exit: none of the parent's destructors or atexit handlers runs here.
    ::close(data[0]), ::close(text[0]);
    // The parent's crash handlers (a test framework's, a driver's) must not run in this copy of it.
    for (int sig : {SIGSEGV, SIGABRT, SIGBUS, SIGFPE, SIGILL}) std::signal(sig, SIG_DFL);
    ::dup2(text[1], STDOUT_FILENO);
    std::setvbuf(stdout, nullptr, _IONBF, 0);
    std::int32_t status = 0;
    TetgenOutput out;
    try {
      out = run_here(in, command);
    } catch (const std::exception& e) {
      status = 1;
      std::printf("\n%s\n", e.what());
    }
    bool ok = write_all(data[1], &status, sizeof status);
    if (ok && status == 0)
      ok = write_array(data[1], out.points) && write_array(data[1], out.tets) && write_array(data[1], out.faces) &&
           write_array(data[1], out.markers);
    ::_exit(ok ? 0 : 3);
  }
  ::close(data[1]), ::close(text[1]);
  std::string buffer, said;
  drain(data[0], text[0], buffer, said);
  int wstatus = 0;
  while (::waitpid(pid, &wstatus, 0) < 0 && errno == EINTR) {
  }

  if (WIFSIGNALED(wstatus)) {
    int sig = WTERMSIG(wstatus);
    std::string last = last_lines(said, 4);
    throw InputError(fmt::format(
        "tetrahedralize: TetGen crashed ({}) on this surface — Debian's TetGen 1.5.0 does not survive its own errors; "
        "it said: \"{}\" (switches -{})",
        sig == SIGSEGV   ? "SIGSEGV"
        : sig == SIGABRT ? "SIGABRT: a failed assertion or a double free"
                         : fmt::format("signal {}", sig),
        last.empty() ? "nothing" : last, command));
  }
  std::int32_t status = -1;
  std::size_t at = 0;
  if (buffer.size() >= sizeof status) std::memcpy(&status, buffer.data(), sizeof status), at = sizeof status;
  if (status == 1) throw InputError(last_lines(said, 1));  // run_here's message, already an InputError's
  TetgenOutput out;
  if (status != 0 || !WIFEXITED(wstatus) || WEXITSTATUS(wstatus) != 0 || !read_array(buffer, at, out.points) ||
      !read_array(buffer, at, out.tets) || !read_array(buffer, at, out.faces) || !read_array(buffer, at, out.markers))
    throw InputError(fmt::format("tetrahedralize: the TetGen process failed (exit status {}); it said: \"{}\"",
                                 WIFEXITED(wstatus) ? WEXITSTATUS(wstatus) : -1, last_lines(said, 4)));
  return out;
}

}  // namespace

double tet_volume(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return OpenMesh::dot(b - a, OpenMesh::cross(c - a, d - a)) / 6.0;
}

VolumeMesh tetrahedralize(const SurfaceMesh& surface, const TetrahedralizeOptions& options) {
  std::string command = switches(options);
  check_solid_surface(surface, {.self_intersections = options.check_self_intersections}, "tetrahedralize");

  const int nv = int(surface.n_vertices());
  const int nf = int(surface.n_faces());
  tetgenio in;  // its destructor frees every list (allocated with new[], as TetGen expects)
  in.firstnumber = 0;
  in.numberofpoints = nv;
  in.pointlist = new REAL[std::size_t(3 * nv)];
  for (auto v : surface.vertices())
    for (int k = 0; k < 3; ++k) in.pointlist[3 * v.idx() + k] = surface.point(v)[k];
  in.numberoffacets = nf;
  in.facetlist = new tetgenio::facet[std::size_t(nf)];
  in.facetmarkerlist = new int[std::size_t(nf)];
  for (auto f : surface.faces()) {
    tetgenio::facet& facet = in.facetlist[f.idx()];
    tetgenio::init(&facet);
    facet.numberofpolygons = 1;
    facet.polygonlist = new tetgenio::polygon[1];
    tetgenio::init(&facet.polygonlist[0]);
    facet.polygonlist[0].numberofvertices = 3;
    facet.polygonlist[0].vertexlist = new int[3];
    int k = 0;
    for (auto v : surface.fv_range(f)) facet.polygonlist[0].vertexlist[k++] = v.idx();
    in.facetmarkerlist[f.idx()] = f.idx() + 1;  // marker 0 is TetGen's "no marker": shift by one
  }

  TetgenOutput out = options.isolate ? run_isolated(in, command) : run_here(in, command);
  const int n_points = int(out.points.size() / 3), n_tets = int(out.tets.size() / 4);
  const int n_faces = int(out.faces.size() / 3);

  // TetGen keeps the input points first and in order unless it removes duplicate or unused ones,
  // which check_solid_surface excludes; verify rather than trust.
  if (n_points < nv || n_tets <= 0)
    throw InputError(fmt::format("tetrahedralize: TetGen returned {} points (of {} on the surface) and {} tetrahedra",
                                 n_points, nv, n_tets));
  for (int i = 0; i < 3 * nv; ++i)
    if (out.points[std::size_t(i)] != in.pointlist[i])
      throw std::logic_error(fmt::format("tetrahedralize: TetGen moved or renumbered surface vertex {}", i / 3));

  VolumeMesh mesh;
  mesh.n_surface_vertices = nv;
  mesh.points.resize(std::size_t(n_points));
  for (std::size_t i = 0; i < std::size_t(n_points); ++i)
    mesh.points[i] = Vec3(out.points[3 * i], out.points[3 * i + 1], out.points[3 * i + 2]);
  mesh.tets.resize(std::size_t(n_tets));
  for (std::size_t t = 0; t < std::size_t(n_tets); ++t) {
    auto& tet = mesh.tets[t];
    for (std::size_t k = 0; k < 4; ++k) {
      tet[k] = out.tets[4 * t + k];
      if (tet[k] < 0 || tet[k] >= n_points) throw std::logic_error("tetrahedralize: TetGen returned a bad vertex index");
    }
    const auto& P = mesh.points;
    if (tet_volume(P[std::size_t(tet[0])], P[std::size_t(tet[1])], P[std::size_t(tet[2])], P[std::size_t(tet[3])]) < 0)
      std::swap(tet[2], tet[3]);
  }

  // Boundary faces: with -Y, exactly the input triangles, each carrying its face's marker. Take the
  // surface's own (outward) vertex order, after checking that TetGen's faces are the same triangles.
  if (n_faces != nf || out.markers.size() != std::size_t(nf))
    throw InputError(fmt::format("tetrahedralize: TetGen returned {} boundary faces for {} surface faces (switches -{})",
                                 n_faces, nf, command));
  std::vector<char> seen(std::size_t(nf), 0);
  for (std::size_t i = 0; i < std::size_t(nf); ++i) {
    int f = out.markers[i] - 1;
    if (f < 0 || f >= nf || seen[std::size_t(f)])
      throw std::logic_error(fmt::format("tetrahedralize: TetGen boundary face {} has marker {}", i, f + 1));
    seen[std::size_t(f)] = 1;
    std::array<int, 3> a{out.faces[3 * i], out.faces[3 * i + 1], out.faces[3 * i + 2]};
    const int* input = in.facetlist[f].polygonlist[0].vertexlist;
    std::array<int, 3> b{input[0], input[1], input[2]};
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    if (a != b)
      throw InputError(fmt::format("tetrahedralize: TetGen changed surface face {} (switches -{})", f, command));
  }
  mesh.boundary_faces.resize(std::size_t(nf));
  mesh.boundary_source_face.resize(std::size_t(nf));
  for (auto f : surface.faces()) {
    int k = 0;
    for (auto v : surface.fv_range(f)) mesh.boundary_faces[std::size_t(f.idx())][std::size_t(k++)] = v.idx();
    mesh.boundary_source_face[std::size_t(f.idx())] = f.idx();
  }
  return mesh;
}

VolumeStats volume_stats(const VolumeMesh& mesh) {
  VolumeStats s;
  s.vertices = mesh.points.size();
  s.tets = mesh.tets.size();
  s.boundary_faces = mesh.boundary_faces.size();
  s.min_dihedral_deg = 180;
  s.max_dihedral_deg = 0;
  double edge_sum = 0;
  static constexpr int kEdges[6][4] = {{0, 1, 2, 3}, {0, 2, 1, 3}, {0, 3, 1, 2}, {1, 2, 0, 3}, {1, 3, 0, 2}, {2, 3, 0, 1}};
  for (const auto& t : mesh.tets) {
    std::array<Vec3, 4> p;
    for (int k = 0; k < 4; ++k) p[std::size_t(k)] = mesh.points[std::size_t(t[std::size_t(k)])];
    s.volume += tet_volume(p[0], p[1], p[2], p[3]);
    for (const auto& e : kEdges) {
      // Dihedral angle at edge (a, b) between the faces through c and through d.
      const Vec3 &a = p[std::size_t(e[0])], &b = p[std::size_t(e[1])], &c = p[std::size_t(e[2])],
                 &d = p[std::size_t(e[3])];
      Vec3 axis = (b - a).normalized();
      Vec3 u = (c - a) - axis * OpenMesh::dot(c - a, axis);
      Vec3 w = (d - a) - axis * OpenMesh::dot(d - a, axis);
      double cosine = std::clamp(OpenMesh::dot(u, w) / (u.norm() * w.norm()), -1.0, 1.0);
      double angle = std::acos(cosine) * 180 / std::numbers::pi;
      s.min_dihedral_deg = std::min(s.min_dihedral_deg, angle);
      s.max_dihedral_deg = std::max(s.max_dihedral_deg, angle);
      edge_sum += (b - a).norm();
    }
  }
  s.mean_edge = mesh.tets.empty() ? 0 : edge_sum / (6.0 * double(mesh.tets.size()));
  return s;
}

}  // namespace bodyfit::thermal
