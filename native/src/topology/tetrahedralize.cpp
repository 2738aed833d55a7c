#include "topstoc/topology/tetrahedralize.hpp"

#include <tetgen.h>

#include "topstoc/core/self_intersections.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>

#if defined(__unix__) || defined(__APPLE__)
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>
#define TOPSTOC_TETGEN_IN_CHILD 1
#endif

namespace topstoc {

namespace {

std::string tetgen_reason(int code) {
  switch (code) {
    case 1: return "TetGen ran out of memory";
    case 2: return "TetGen hit an internal error on this surface";
    case 3: return "the surface intersects itself (TetGen found two triangles crossing each other)";
    case 4: return "the surface has a feature too small for TetGen (nearly coincident vertices or edges)";
    case 5: return "the surface has two nearly coincident or overlapping triangles";
    case 10: return "TetGen rejected the surface as invalid input";
    default: return "TetGen failed with code " + std::to_string(code);
  }
}

// The tetgenio structures free their arrays with delete[]; ours are borrowed from vectors, so
// the pointers are detached again before the structure is destroyed.
struct BorrowedInput {
  tetgenio io;
  ~BorrowedInput() {
    io.pointlist = nullptr;
    io.numberofpoints = 0;
    io.facetlist = nullptr;
    io.numberoffacets = 0;
  }
};

// What TetGen printed before failing names the offending triangles: "1st: [a, b, c] #i".
void parse_triangles(const std::string& text, std::vector<int32_t>& vertices) {
  for (const char* tag : {"1st: [", "2nd: ["}) {
    const size_t at = text.find(tag);
    int a, b, c;
    if (at != std::string::npos && std::sscanf(text.c_str() + at + 6, "%d, %d, %d", &a, &b, &c) == 3)
      vertices.insert(vertices.end(), {a, b, c});
  }
}

[[noreturn]] void refuse(int code, const std::string& text) {
  std::string why = tetgen_reason(code);
  if (code != 3 && text.find("intersect") != std::string::npos) {
    code = 3;
    why = tetgen_reason(3);
  }
  std::vector<int32_t> vertices;
  parse_triangles(text, vertices);
  throw TetgenRefused(code, why, vertices);
}

#ifdef TOPSTOC_TETGEN_IN_CHILD
// TetGen 1.5 frees its memory twice when it gives up (terminatetetgen() frees, then the
// destructor frees again) and the process crashes. So it runs in a forked child that sends its
// result through a pipe: a failure becomes an exit we can report, and a long run can be
// cancelled by killing the child. The child touches nothing but TetGen and leaves with _exit.
bool write_all(int fd, const void* data, size_t size) {
  const char* p = static_cast<const char*>(data);
  while (size) {
    const ssize_t n = write(fd, p, size);
    if (n <= 0) return false;
    p += n;
    size -= size_t(n);
  }
  return true;
}

// TetGen computes without blocking, so a child that neither runs nor sends for this long is
// stuck: its double free on refusal, which usually aborts it, once left it waiting forever on a
// lock read from the freed memory (a test of a self-intersecting surface hung in the child's free).
constexpr auto kStuck = std::chrono::seconds(5);

// The child's CPU ticks (user + system) and whether it is running, from /proc/<pid>/stat; false
// where there is no /proc (then no child is ever judged stuck).
bool child_cpu(pid_t child, unsigned long long& ticks, bool& running) {
  char path[64];
  std::snprintf(path, sizeof path, "/proc/%d/stat", int(child));
  FILE* file = std::fopen(path, "r");
  if (!file) return false;
  char line[1024];
  const size_t n = std::fread(line, 1, sizeof line - 1, file);
  std::fclose(file);
  line[n] = 0;
  const char* after_name = std::strrchr(line, ')');  // the name may hold spaces and brackets
  char state = 0;
  unsigned long long user = 0, system = 0;
  if (!after_name || std::sscanf(after_name + 2, "%c %*d %*d %*d %*d %*d %*u %*u %*u %*u %*u %llu %llu", &state,
                                 &user, &system) != 3)
    return false;
  ticks = user + system;
  running = state == 'R';
  return true;
}

void run_tetgen(tetgenio& in, std::vector<double>& points, std::vector<int32_t>& tets, Progress* progress) {
  int data[2], text[2];
  if (pipe(data) != 0) throw std::runtime_error("cannot create a pipe for TetGen");
  if (pipe(text) != 0) {
    close(data[0]);
    close(data[1]);
    throw std::runtime_error("cannot create a pipe for TetGen");
  }
  std::fflush(stdout);
  std::fflush(stderr);
  const pid_t child = fork();
  if (child < 0) {
    for (int fd : {data[0], data[1], text[0], text[1]}) close(fd);
    throw std::runtime_error("cannot start a process for TetGen");
  }
  if (child == 0) {
    // The host's crash handlers (Python's faulthandler) would print for TetGen's crash on refusal.
    for (int sig : {SIGSEGV, SIGABRT, SIGBUS, SIGFPE, SIGILL}) signal(sig, SIG_DFL);
    close(data[0]);
    close(text[0]);
    dup2(text[1], 1);
    dup2(text[1], 2);
    std::setvbuf(stdout, nullptr, _IONBF, 0);  // TetGen's last words must reach the pipe before a crash
    int64_t header[3] = {0, 0, 0};
    tetgenio out;
    char switches[] = "pYQO0";
    try {
      tetrahedralize(switches, &in, &out);
    } catch (int code) {
      header[0] = code;
    } catch (...) {
      header[0] = 2;
    }
    if (header[0] == 0) {
      header[1] = out.numberofpoints;
      header[2] = out.numberoftetrahedra;
    }
    const bool ok = write_all(data[1], header, sizeof header) &&
                    write_all(data[1], out.pointlist, sizeof(double) * 3 * size_t(header[1])) &&
                    write_all(data[1], out.tetrahedronlist, sizeof(int) * 4 * size_t(header[2]));
    _exit(ok ? 0 : 1);
  }
  close(data[1]);
  close(text[1]);
  // Read both pipes until the child closes them, reporting progress (which may cancel).
  std::string bytes, messages;
  bool data_open = true, text_open = true;
  char buffer[1 << 16];
  // A stuck child (kStuck) is killed; its exit is then reported as TetGen's failure below.
  unsigned long long last_ticks = 0;
  auto last_sign = std::chrono::steady_clock::now();
  try {
    while (data_open || text_open) {
      pollfd fds[2] = {{data[0], POLLIN, 0}, {text[0], POLLIN, 0}};
      poll(fds, 2, 50);
      if (progress) progress->update(0.5);
      for (int i = 0; i < 2; ++i) {
        bool& open = i == 0 ? data_open : text_open;
        if (!open || !(fds[i].revents & (POLLIN | POLLHUP | POLLERR))) continue;
        const ssize_t n = read(fds[i].fd, buffer, sizeof buffer);
        if (n > 0)
          (i == 0 ? bytes : messages).append(buffer, size_t(n)), last_sign = std::chrono::steady_clock::now();
        else
          open = false;
      }
      unsigned long long ticks = 0;
      bool running = false;
      if (!child_cpu(child, ticks, running)) continue;
      if (running || ticks != last_ticks) {
        last_ticks = ticks;
        last_sign = std::chrono::steady_clock::now();
      } else if (std::chrono::steady_clock::now() - last_sign > kStuck) {
        kill(child, SIGKILL);
        break;
      }
    }
  } catch (...) {
    kill(child, SIGKILL);
    waitpid(child, nullptr, 0);
    close(data[0]);
    close(text[0]);
    throw;
  }
  close(data[0]);
  close(text[0]);
  int status = 0;
  waitpid(child, &status, 0);
  int64_t header[3] = {0, 0, 0};
  if (bytes.size() >= sizeof header) std::memcpy(header, bytes.data(), sizeof header);
  const size_t expected = sizeof header + sizeof(double) * 3 * size_t(header[1]) + sizeof(int) * 4 * size_t(header[2]);
  if (bytes.size() < sizeof header || header[0] != 0 || bytes.size() != expected || !WIFEXITED(status) ||
      WEXITSTATUS(status) != 0)
    refuse(header[0] ? int(header[0]) : 2, messages);
  points.resize(3 * size_t(header[1]));
  std::memcpy(points.data(), bytes.data() + sizeof header, sizeof(double) * points.size());
  std::vector<int> corners(4 * size_t(header[2]));
  std::memcpy(corners.data(), bytes.data() + sizeof header + sizeof(double) * points.size(), sizeof(int) * corners.size());
  tets.assign(corners.begin(), corners.end());
}
#else
void run_tetgen(tetgenio& in, std::vector<double>& points, std::vector<int32_t>& tets, Progress*) {
  tetgenio out;
  char switches[] = "pYQO0";
  try {
    tetrahedralize(switches, &in, &out);
  } catch (int code) {
    refuse(code, "");
  }
  points.assign(out.pointlist, out.pointlist + 3 * size_t(out.numberofpoints));
  tets.assign(out.tetrahedronlist, out.tetrahedronlist + 4 * size_t(out.numberoftetrahedra));
}
#endif

struct FaceKey {
  std::array<int32_t, 3> v;
  int32_t tet;
  bool operator<(const FaceKey& o) const { return v < o.v; }
};

std::array<int32_t, 3> sorted3(int32_t a, int32_t b, int32_t c) {
  std::array<int32_t, 3> k{a, b, c};
  std::sort(k.begin(), k.end());
  return k;
}

// TetGen refuses a self-intersecting surface, often by crashing without a word: name the
// first offending pair instead.
void refuse_self_intersections(const double* positions, int32_t num_vertices, const int32_t* triangles,
                               int32_t num_triangles) {
  const auto crossing = self_intersections(positions, num_vertices, triangles, num_triangles, 1);
  if (crossing.empty()) return;
  const auto [a, b] = crossing.front();
  std::vector<int32_t> vertices(triangles + 3 * size_t(a), triangles + 3 * size_t(a) + 3);
  if (a == b) throw TetgenRefused(4, "the surface has a triangle without area", vertices);
  vertices.insert(vertices.end(), triangles + 3 * size_t(b), triangles + 3 * size_t(b) + 3);
  throw TetgenRefused(3, "the surface intersects itself", vertices);
}

// TetGen's input: the surface's vertices, then the 8 corners of a box around it; the
// surface's triangles, then the box's 6 quads. Fills mesh.points and mesh.tets.
void tetrahedralize_in_box(const std::vector<double>& tetgen_positions, const double* positions, int32_t num_vertices,
                           const int32_t* triangles, int32_t num_triangles, Progress* progress, TetMesh& mesh) {
  std::vector<double> points(tetgen_positions);
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (int32_t v = 0; v < num_vertices; ++v)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], positions[3 * size_t(v) + k]);
      hi[k] = std::max(hi[k], positions[3 * size_t(v) + k]);
    }
  double margin = 0.0;
  for (int k = 0; k < 3; ++k) margin = std::max(margin, 0.1 * (hi[k] - lo[k]));
  if (!(margin > 0)) margin = 1.0;
  for (int corner = 0; corner < 8; ++corner)
    for (int k = 0; k < 3; ++k) points.push_back((corner >> k) & 1 ? hi[k] + margin : lo[k] - margin);
  static const int kBoxQuads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  std::vector<int32_t> box(24);
  for (int q = 0; q < 6; ++q)
    for (int k = 0; k < 4; ++k) box[4 * q + k] = num_vertices + kBoxQuads[q][k];

  std::vector<int32_t> corners(triangles, triangles + 3 * size_t(num_triangles));
  std::vector<tetgenio::polygon> polygons(size_t(num_triangles) + 6);
  std::vector<tetgenio::facet> facets(polygons.size());
  for (size_t i = 0; i < polygons.size(); ++i) {
    const bool is_box = i >= size_t(num_triangles);
    polygons[i].vertexlist = is_box ? &box[4 * (i - num_triangles)] : &corners[3 * i];
    polygons[i].numberofvertices = is_box ? 4 : 3;
    facets[i].polygonlist = &polygons[i];
    facets[i].numberofpolygons = 1;
    facets[i].holelist = nullptr;
    facets[i].numberofholes = 0;
  }
  BorrowedInput in;
  in.io.firstnumber = 0;
  in.io.pointlist = points.data();
  in.io.numberofpoints = num_vertices + 8;
  in.io.facetlist = facets.data();
  in.io.numberoffacets = int(facets.size());
  run_tetgen(in.io, mesh.points, mesh.tets, progress);
  if (mesh.points.size() < 3 * size_t(num_vertices)) throw TetgenRefused(0, "TetGen lost surface vertices");
  for (size_t i = 0; i < 3 * size_t(num_vertices); ++i)
    if (mesh.points[i] != tetgen_positions[i]) throw TetgenRefused(0, "TetGen moved or renumbered a surface vertex");
  std::copy(positions, positions + 3 * size_t(num_vertices), mesh.points.begin());
}

// Distinct faces of the tetrahedra (numbered in sorted corner order) and each tetrahedron's
// faces; returns the (one or two) tetrahedra of each face, 2 per face, -1 for a face on the box.
std::vector<int32_t> number_faces(TetMesh& mesh) {
  const int32_t num_tets = mesh.num_tets();
  std::vector<FaceKey> keys(4 * size_t(num_tets));
  for (int32_t t = 0; t < num_tets; ++t) {
    const int32_t* c = &mesh.tets[4 * size_t(t)];
    for (int k = 0; k < 4; ++k)
      keys[4 * size_t(t) + k] = {sorted3(c[(k + 1) % 4], c[(k + 2) % 4], c[(k + 3) % 4]), t};
  }
  std::sort(keys.begin(), keys.end());
  mesh.tet_faces.assign(4 * size_t(num_tets), -1);
  std::vector<int32_t> face_tets;
  for (size_t i = 0; i < keys.size();) {
    size_t j = i;
    while (j < keys.size() && keys[j].v == keys[i].v) ++j;
    if (j - i > 2) throw TetgenRefused(0, "TetGen returned a triangle shared by more than two tetrahedra");
    const int32_t f = mesh.num_faces();
    mesh.faces.insert(mesh.faces.end(), keys[i].v.begin(), keys[i].v.end());
    face_tets.push_back(keys[i].tet);
    face_tets.push_back(j - i == 2 ? keys[i + 1].tet : -1);
    for (size_t k = i; k < j; ++k) {
      const int32_t* c = &mesh.tets[4 * size_t(keys[k].tet)];
      for (int s = 0; s < 4; ++s)
        if (sorted3(c[(s + 1) % 4], c[(s + 2) % 4], c[(s + 3) % 4]) == keys[i].v) mesh.tet_faces[4 * size_t(keys[k].tet) + s] = f;
    }
    i = j;
  }
  return face_tets;
}

// The face with these sorted corners (faces are in sorted key order: binary search), or -1.
int32_t face_of(const TetMesh& mesh, const std::array<int32_t, 3>& key) {
  int32_t lo = 0, hi = mesh.num_faces();
  while (lo < hi) {
    const int32_t mid = lo + (hi - lo) / 2;
    const std::array<int32_t, 3> at{mesh.faces[3 * size_t(mid)], mesh.faces[3 * size_t(mid) + 1], mesh.faces[3 * size_t(mid) + 2]};
    if (at < key) lo = mid + 1; else hi = mid;
  }
  const bool found = lo < mesh.num_faces() && mesh.faces[3 * size_t(lo)] == key[0] &&
                     mesh.faces[3 * size_t(lo) + 1] == key[1] && mesh.faces[3 * size_t(lo) + 2] == key[2];
  return found ? lo : -1;
}

// The surface triangles among the faces (mesh.surface_face); returns per face whether it is one.
std::vector<uint8_t> find_surface_faces(TetMesh& mesh, const int32_t* triangles, int32_t num_triangles) {
  std::vector<uint8_t> on_surface(mesh.num_faces(), 0);
  mesh.surface_face.resize(num_triangles);
  for (int32_t t = 0; t < num_triangles; ++t) {
    const int32_t f = face_of(mesh, sorted3(triangles[3 * size_t(t)], triangles[3 * size_t(t) + 1], triangles[3 * size_t(t) + 2]));
    if (f < 0) throw TetgenRefused(0, "TetGen did not keep surface triangle " + std::to_string(t));
    mesh.surface_face[t] = f;
    on_surface[f] = 1;
  }
  return on_surface;
}

// Flood fill from the box, never across the surface: reached tetrahedra are outside.
void mark_outside(TetMesh& mesh, const std::vector<int32_t>& face_tets, const std::vector<uint8_t>& on_surface) {
  mesh.inside.assign(mesh.num_tets(), 1);
  std::vector<int32_t> stack;
  for (int32_t f = 0; f < mesh.num_faces(); ++f)
    if (face_tets[2 * size_t(f) + 1] < 0 && mesh.inside[face_tets[2 * size_t(f)]]) {
      if (on_surface[f]) throw TetgenRefused(0, "the surface touches the bounding box");
      mesh.inside[face_tets[2 * size_t(f)]] = 0;
      stack.push_back(face_tets[2 * size_t(f)]);
    }
  while (!stack.empty()) {
    const int32_t t = stack.back();
    stack.pop_back();
    for (int s = 0; s < 4; ++s) {
      const int32_t f = mesh.tet_faces[4 * size_t(t) + s];
      if (on_surface[f]) continue;
      const int32_t u = face_tets[2 * size_t(f)] == t ? face_tets[2 * size_t(f) + 1] : face_tets[2 * size_t(f)];
      if (u >= 0 && mesh.inside[u]) {
        mesh.inside[u] = 0;
        stack.push_back(u);
      }
    }
  }
}

// TetGen on the given positions for the surface's vertices, then the faces, the sides and the
// check that every surface triangle separates inside from outside.
void tetrahedralize_at(const std::vector<double>& tetgen_positions, const double* positions, int32_t num_vertices,
                       const int32_t* triangles, int32_t num_triangles, Progress* progress, TetMesh& mesh) {
  tetrahedralize_in_box(tetgen_positions, positions, num_vertices, triangles, num_triangles, progress, mesh);
  const auto face_tets = number_faces(mesh);
  const auto on_surface = find_surface_faces(mesh, triangles, num_triangles);
  mark_outside(mesh, face_tets, on_surface);
  // A closed embedded surface has exactly one tetrahedron on each side of each of its triangles.
  for (int32_t t = 0; t < num_triangles; ++t) {
    const int32_t f = mesh.surface_face[t];
    const int32_t a = face_tets[2 * size_t(f)], b = face_tets[2 * size_t(f) + 1];
    if (b < 0 || mesh.inside[a] == mesh.inside[b])
      throw TetgenRefused(0, "surface triangle " + std::to_string(t) +
                                 " does not separate inside from outside (the surface is not the boundary of a solid)");
  }
}

}  // namespace

std::vector<double> tetgen_perturbation(const double* positions, int32_t num_vertices, const int32_t* triangles,
                                        int32_t num_triangles) {
  std::vector<double> shortest(num_vertices, INFINITY);
  for (int32_t t = 0; t < num_triangles; ++t)
    for (int k = 0; k < 3; ++k) {
      const int32_t a = triangles[3 * size_t(t) + k], b = triangles[3 * size_t(t) + (k + 1) % 3];
      double d2 = 0.0;
      for (int c = 0; c < 3; ++c) d2 += (positions[3 * size_t(a) + c] - positions[3 * size_t(b) + c]) *
                                        (positions[3 * size_t(a) + c] - positions[3 * size_t(b) + c]);
      shortest[a] = std::min(shortest[a], std::sqrt(d2));
      shortest[b] = std::min(shortest[b], std::sqrt(d2));
    }
  std::vector<double> moved(positions, positions + 3 * size_t(num_vertices));
  for (size_t i = 0; i < moved.size(); ++i) {
    const double scale = std::isfinite(shortest[i / 3]) ? kTetgenPerturbation * shortest[i / 3] : 0.0;
    uint64_t z = (uint64_t(i) + 1) * 0x9E3779B97F4A7C15ull;  // splitmix64: a fixed pseudo-random sign and size
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    moved[i] += scale * (double(z >> 11) * 0x1.0p-52 - 1.0);  // uniform in [-scale, scale)
  }
  return moved;
}

TetMesh tetrahedralize_surface(const double* positions, int32_t num_vertices, const int32_t* triangles,
                               int32_t num_triangles, Progress* progress) {
  const auto check_start = std::chrono::steady_clock::now();
  refuse_self_intersections(positions, num_vertices, triangles, num_triangles);
  const double seconds_check = std::chrono::duration<double>(std::chrono::steady_clock::now() - check_start).count();
  // Perturbed positions first (TetGen's exact arithmetic on coplanar and cospherical vertices is
  // slow); if TetGen refuses them, the exact positions decide.
  for (const bool perturbed : {true, false}) {
    TetMesh mesh;
    mesh.num_surface_points = num_vertices;
    mesh.seconds_check = seconds_check;
    try {
      const std::vector<double> at = perturbed ? tetgen_perturbation(positions, num_vertices, triangles, num_triangles)
                                                : std::vector<double>(positions, positions + 3 * size_t(num_vertices));
      tetrahedralize_at(at, positions, num_vertices, triangles, num_triangles, progress, mesh);
      mesh.perturbed = perturbed;
      return mesh;
    } catch (const TetgenRefused&) {
      if (!perturbed) throw;
    }
  }
  throw std::logic_error("unreachable");
}

}  // namespace topstoc
