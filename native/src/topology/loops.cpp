#include "topstoc/topology/loops.hpp"

#include <algorithm>
#include <chrono>
#include <memory>
#include <numeric>
#include <stdexcept>

#include "topology/coarse_surface.hpp"
#include "topology/homology.hpp"
#include "topology/loop_basis.hpp"
#include "topology/loop_mapping.hpp"
#include "topology/loop_shortening.hpp"
#include "topology/persistence.hpp"
#include "topology/closed_surface.hpp"
#include "topstoc/core/parallel.hpp"
#include "topstoc/topology/tetrahedralize.hpp"

namespace topstoc {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

std::vector<double> edge_weights(const ClosedSurface& s, bool count_edges) {
  std::vector<double> w(s.num_edges(), 1.0);
  if (!count_edges)
    for (int32_t e = 0; e < s.num_edges(); ++e) w[e] = s.edge_length(e);
  return w;
}

int32_t local_id(const std::vector<int32_t>& sorted, int32_t id) {
  const auto it = std::lower_bound(sorted.begin(), sorted.end(), id);
  return it != sorted.end() && *it == id ? int32_t(it - sorted.begin()) : -1;
}

// The coarse surface standing for one full component, with the cluster of every full vertex
// and the full vertex behind every coarse one. Empty `why` on success.
struct CoarseView {
  ClosedSurface surface;
  std::vector<int32_t> cluster_of, representative;
  std::string why;
};

CoarseView coarse_view(const Mesh& mesh, const std::vector<int32_t>& fine_vertices, const ClosedSurface& fine,
                       int32_t fine_component, int32_t genus, const CoarseMesh& coarse) {
  CoarseView view;
  int32_t found = -1, count = 0;
  for (size_t c = 0; c < coarse.fine_component.size(); ++c)
    if (coarse.fine_component[c] == fine_component) {
      found = int32_t(c);
      ++count;
    }
  if (count != 1) {
    view.why = "the decimation split or lost the component";
    return view;
  }
  const SurfaceCheck& check = coarse.checks[found];
  if (!check.problem.empty() || check.genus() != genus) {
    view.why = "the decimation changed the component's topology";
    return view;
  }
  view.surface = extract_surface(*coarse.mesh, coarse.components[found]);
  const Mesh& cm = *coarse.mesh;
  const auto& labels = coarse.decimation.labels;
  view.cluster_of.resize(fine.num_vertices());
  for (int32_t v = 0; v < fine.num_vertices(); ++v) {
    const int32_t output_vertex = labels[mesh.vertex_source()[fine.mesh_vertex[v]]];
    const int32_t c = output_vertex < 0 ? -1 : local_id(coarse.components[found], cm.vertex_index()[output_vertex]);
    if (c < 0) {
      view.why = "a vertex has no cluster in the component";
      return view;
    }
    view.cluster_of[v] = c;
  }
  view.representative.resize(view.surface.num_vertices());
  for (int32_t c = 0; c < view.surface.num_vertices(); ++c) {
    const int32_t output_vertex = cm.vertex_source()[view.surface.mesh_vertex[c]];
    const int32_t v = local_id(fine_vertices, mesh.vertex_index()[coarse.decimation.kept[output_vertex]]);
    if (v < 0 || view.cluster_of[v] != c) {
      view.why = "a cluster does not hold its own sample";
      return view;
    }
    view.representative[c] = v;
  }
  return view;
}

struct Analysis {
  std::vector<SelectedLoop> loops;
  int32_t tetrahedra = 0;
};

// Steps 1-3 on one surface; `begin`..`end` is its share of the progress bar.
Analysis analyse(const ClosedSurface& s, const std::vector<double>& weight, const LoopParams& params, Progress& progress,
                 LoopsResult& r, double begin, double end) {
  auto at = [&](double f) { return begin + (end - begin) * f; };
  Analysis a;
  auto start = Clock::now();
  progress.stage("tetrahedralize", at(0.0), at(0.5));
  const TetMesh tets = tetrahedralize_surface(s.positions.data(), s.num_vertices(), s.triangles.data(), s.num_faces(), &progress);
  a.tetrahedra = tets.num_tets();
  r.seconds_intersections += tets.seconds_check;
  r.seconds_tetrahedralize += seconds_since(start) - tets.seconds_check;
  start = Clock::now();
  progress.stage("persistence", at(0.5), at(0.7));
  const auto cycles = handle_tunnel_cycles(s, tets, &progress);
  r.seconds_persistence += seconds_since(start);
  start = Clock::now();
  progress.stage("select loops", at(0.7), at(1.0));
  const SurfaceHomology homology(s);
  a.loops = select_loops(s, homology, cycles, weight, params.max_roots, &progress);
  r.seconds_select += seconds_since(start);
  return a;
}

void check_simple(const ClosedSurface& s, const std::vector<int32_t>& loop, std::vector<uint8_t>& seen) {
  if (loop.size() < 3) throw std::logic_error("a loop has fewer than three edges");
  for (size_t i = 0; i < loop.size(); ++i) {
    if (seen[loop[i]]) throw std::logic_error("a loop visits a vertex twice");
    seen[loop[i]] = 1;
    if (s.find_edge(loop[i], loop[(i + 1) % loop.size()]) < 0) throw std::logic_error("a loop steps off the mesh edges");
  }
  for (int32_t v : loop) seen[v] = 0;
}

// TetGen's reason, with the triangles it named in the caller's vertex ids.
template <class ToCaller>
std::string refusal_message(const TetgenRefused& refused, ToCaller to_caller) {
  std::string message = refused.what();
  const auto& v = refused.vertices();
  auto triangle = [&](size_t i) {
    return "(" + std::to_string(to_caller(v[i])) + ", " + std::to_string(to_caller(v[i + 1])) + ", " +
           std::to_string(to_caller(v[i + 2])) + ")";
  };
  if (v.size() >= 6)
    message += ": triangles " + triangle(0) + " and " + triangle(3);
  else if (v.size() == 3)
    message += ": triangle " + triangle(0);
  return message;
}

std::string component_name(size_t index, const SurfaceCheck& check) {
  return "component " + std::to_string(index) + " (from vertex " + std::to_string(check.first_vertex) + ")";
}

// The loops found on one component's full surface (fine ids), by either route, before
// shortening: the loops, the edge each crosses, and whether it is a handle.
struct FoundLoops {
  std::vector<std::vector<int32_t>> loops;
  std::vector<std::pair<int32_t, int32_t>> generators;
  std::vector<uint8_t> is_handle;
  void clear() { loops.clear(), generators.clear(), is_handle.clear(); }
};

// One component's work: its full surface, its share of the progress bar, and what it found.
struct ComponentJob {
  int32_t k;  // index into result.components
  ComponentLoops& out;
  const SurfaceCheck& check;
  int32_t fine_component;
  double begin, end;
  ClosedSurface fine;
  std::vector<double> fine_weight;
  FoundLoops found;
  double at(double f) const { return begin + (end - begin) * f; }
};

// One run of compute_loops: the components to analyse, the coarse decimations made for them,
// and the result being filled. The stages run in the order of run().
class LoopsComputation {
 public:
  LoopsComputation(const Mesh& mesh, const LoopParams& params) : mesh(mesh), params(params), progress(params.progress) {}

  LoopsResult run() {
    const auto start = Clock::now();
    progress.stage("prepare", 0.0, 0.03);
    components = component_vertices(mesh);
    checks = check_closed_surfaces(mesh, components);
    order.resize(components.size());
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](int32_t a, int32_t b) { return checks[a].first_vertex < checks[b].first_vertex; });
    describe_components();
    result.seconds_prepare = seconds_since(start);
    plan_coarse_route();
    int64_t faces_done = 0;
    for (int32_t k : work) {
      ComponentLoops& out = result.components[k];
      const double begin = 0.1 + 0.9 * double(faces_done) / double(work_faces);
      const double end = 0.1 + 0.9 * double(faces_done + out.faces) / double(work_faces);
      faces_done += out.faces;
      ComponentJob job{k, out, checks[order[k]], order[k], begin, end, {}, {}, {}};
      find_component_loops(job);
    }
    progress.stage("done", 1.0, 1.0);
    return std::move(result);
  }

 private:
  const Mesh& mesh;
  const LoopParams& params;
  Progress progress;
  LoopsResult result;
  std::vector<std::vector<int32_t>> components;
  std::vector<SurfaceCheck> checks;
  std::vector<int32_t> order;  // components by first vertex
  std::vector<int32_t> work;   // indices into result.components: closed surfaces of positive genus
  int64_t work_faces = 0;
  int32_t active = 0, base_target = 0;
  std::vector<uint8_t> coarse_wanted;  // per component (mesh order)
  std::vector<std::unique_ptr<CoarseMesh>> levels;

  // Each component's counts and status, in first-vertex order; non-manifold or non-orientable
  // components stop the run.
  void describe_components() {
    for (size_t k = 0; k < order.size(); ++k) {
      const SurfaceCheck& check = checks[order[k]];
      if (check.problem == "non-manifold" || check.problem == "non-orientable")
        throw std::invalid_argument(component_name(k, check) + " is " + check.problem + ": " + check.detail +
                                    "; handle and tunnel loops need closed, orientable, manifold surfaces");
      ComponentLoops c;
      c.first_vertex = check.first_vertex;
      c.vertices = check.vertices;
      c.edges = check.edges;
      c.faces = check.faces;
      c.boundary_loops = check.boundary_loops;
      c.genus = check.genus();
      c.status = check.problem.empty() ? "ok" : check.problem;
      if (check.problem == "open")
        c.detail = "no handle or tunnel loops on an open surface (" + std::to_string(check.boundary_loops) +
                   " boundary loops, " + check.detail + ")";
      if (check.problem.empty() && c.genus > 0) {
        work.push_back(int32_t(k));
        work_faces += c.faces;
      }
      result.components.push_back(std::move(c));
    }
  }

  // Which components take the coarse route (thesis 5.2.2). The automatic target is small:
  // TetGen's time grows with it, and the refinement against self-intersections adds samples
  // where the shape needs them.
  void plan_coarse_route() {
    active = mesh.num_vertices() - mesh.report().isolated_vertices;
    int64_t total_genus = 0;
    for (int32_t k : work) total_genus += result.components[k].genus;
    base_target = params.coarse_vertices > 0
                      ? params.coarse_vertices
                      : int32_t(std::min<int64_t>(active, std::min<int64_t>(20000, 3000 + 100 * total_genus)));
    coarse_wanted.assign(components.size(), 0);
    for (int32_t k : work) {
      const ComponentLoops& c = result.components[k];
      const bool coarse = params.coarse_vertices > 0 || (params.coarse_vertices < 0 && c.faces > params.full_route_faces);
      if (coarse && base_target < c.vertices) coarse_wanted[order[k]] = 1;
    }
  }

  // Coarse decimations, made on first use; each retry doubles the target.
  const CoarseMesh& coarse_level(size_t level) {
    while (levels.size() <= level) {
      const auto t = Clock::now();
      progress.stage("decimate", 0.03, 0.1);
      const int32_t target = int32_t(std::min<int64_t>(active, int64_t(base_target) << levels.size()));
      levels.push_back(make_coarse_mesh(mesh, target, params.seed, coarse_wanted, 10, &progress));
      if (!result.coarse_target) result.coarse_target = target;
      result.coarse_rounds += levels.back()->rounds;
      result.coarse_samples_added += levels.back()->samples_added;
      result.seconds_decimate += seconds_since(t);
    }
    return *levels[level];
  }

  // Steps 1-4 by either route, then step 5 and the checks, on the full surface.
  void find_component_loops(ComponentJob& job) {
    const auto start = Clock::now();
    job.fine = extract_surface(mesh, components[job.fine_component]);
    job.fine_weight = edge_weights(job.fine, params.count_edges);
    result.seconds_prepare += seconds_since(start);
    bool coarse_route = coarse_wanted[job.fine_component];
    if (coarse_route && !loops_by_coarse_route(job)) coarse_route = false;
    if (!coarse_route) loops_by_full_route(job);
    const SurfaceHomology homology(job.fine);
    const auto classes = verify_loops(job, homology);
    shorten_loops(job, homology, classes);
  }

  // Tries the coarse decimations in turn; false when none gave loops (then the full route runs,
  // if the component is small enough).
  bool loops_by_coarse_route(ComponentJob& job) {
    std::string refusal;
    for (size_t level = 0; level < 3; ++level)
      if (loops_on_coarse_level(job, coarse_level(level), refusal)) return true;
    if (job.out.faces > params.max_full_faces)
      throw std::invalid_argument(component_name(job.k, job.check) + ": no coarse version could be tetrahedralized (" +
                                  (refusal.empty() ? std::string("decimation did not keep the topology") : refusal) +
                                  ") and the component is too large to try whole; use coarse_vertices = 0 to force it");
    return false;
  }

  // Steps 1-4 on one coarse decimation, the loops mapped back to the full surface; false (with
  // TetGen's reason in `refusal` when it refused) when this level cannot give them.
  bool loops_on_coarse_level(ComponentJob& job, const CoarseMesh& coarse, std::string& refusal) {
    if (!coarse.topology_kept) return false;
    auto start = Clock::now();
    CoarseView view = coarse_view(mesh, components[job.fine_component], job.fine, job.fine_component, job.out.genus, coarse);
    result.seconds_map += seconds_since(start);
    if (!view.why.empty()) return false;
    Analysis analysis;
    try {
      analysis = analyse(view.surface, edge_weights(view.surface, params.count_edges), params, progress, result,
                         job.at(0.0), job.at(0.6));
    } catch (const TetgenRefused& refused) {
      refusal = refusal_message(refused, [&](int32_t v) {
        if (v < 0 || v >= view.surface.num_vertices()) return -1;
        return coarse.decimation.kept[coarse.mesh->vertex_source()[view.surface.mesh_vertex[v]]];
      });
      refusal += " (on a coarse version)";
      return false;
    }
    // Big moves are cheap on the coarse surface: tighten there first, then only locally.
    start = Clock::now();
    if (params.shorten) {
      progress.stage("shorten (coarse)", job.at(0.55), job.at(0.6));
      const auto coarse_weight = edge_weights(view.surface, params.count_edges);
      const SurfaceHomology coarse_homology(view.surface);
      std::vector<std::vector<int32_t>> loops;
      for (auto& loop : analysis.loops) loops.push_back(std::move(loop.vertices));
      tighten_loops(view.surface, coarse_weight, &coarse_homology, loops, TightenParams{}, &progress);
      for (size_t i = 0; i < loops.size(); ++i) analysis.loops[i].vertices = std::move(loops[i]);
    }
    result.seconds_shorten += seconds_since(start);
    start = Clock::now();
    progress.stage("map to full mesh", job.at(0.6), job.at(0.65));
    ClusterMap map(job.fine, job.fine_weight, std::move(view.cluster_of), std::move(view.representative));
    try {
      job.found.clear();
      for (const auto& loop : analysis.loops) {
        job.found.loops.push_back(map.map_loop(loop.vertices));
        const auto& ev = view.surface.edge_vertices;
        job.found.generators.push_back(
            map.crossing_edge(ev[2 * size_t(loop.generator_edge)], ev[2 * size_t(loop.generator_edge) + 1]));
        job.found.is_handle.push_back(loop.handle);
      }
    } catch (const std::logic_error&) {
      result.seconds_map += seconds_since(start);
      return false;  // clusters not as the decimation promised: try a finer one
    }
    result.seconds_map += seconds_since(start);
    job.out.route = "coarse";
    job.out.analysed_vertices = view.surface.num_vertices();
    job.out.tetrahedra = analysis.tetrahedra;
    return true;
  }

  // Steps 1-4 on the whole component.
  void loops_by_full_route(ComponentJob& job) {
    const ClosedSurface& fine = job.fine;
    Analysis analysis;
    try {
      analysis = analyse(fine, job.fine_weight, params, progress, result, job.at(0.0), job.at(0.65));
    } catch (const TetgenRefused& refused) {
      throw std::invalid_argument(component_name(job.k, job.check) + ": " + refusal_message(refused, [&](int32_t v) {
                                    if (v < 0 || v >= fine.num_vertices()) return -1;
                                    return mesh.vertex_source()[fine.mesh_vertex[v]];
                                  }));
    }
    for (const auto& loop : analysis.loops) {
      job.found.loops.push_back(loop.vertices);
      job.found.generators.emplace_back(fine.edge_vertices[2 * size_t(loop.generator_edge)],
                                        fine.edge_vertices[2 * size_t(loop.generator_edge) + 1]);
      job.found.is_handle.push_back(loop.handle);
    }
    job.out.route = "full";
    job.out.analysed_vertices = fine.num_vertices();
    job.out.tetrahedra = analysis.tetrahedra;
  }

  // Step 5's checks: every loop is simple, there are 2g of them and they span H1. Returns
  // each loop's class.
  std::vector<Z2Vector> verify_loops(const ComponentJob& job, const SurfaceHomology& homology) {
    const auto start = Clock::now();
    progress.stage("verify", job.at(0.65), job.at(0.7));
    std::vector<uint8_t> seen(job.fine.num_vertices(), 0);
    Z2Basis span(homology.dimension());
    std::vector<Z2Vector> classes;
    for (const auto& loop : job.found.loops) {
      check_simple(job.fine, loop, seen);
      classes.push_back(homology.class_of_loop(job.fine, loop));
      if (!span.insert(classes.back()))
        throw std::logic_error(component_name(job.k, job.check) + ": the handle and tunnel loops do not span H1 of the surface");
    }
    if (int32_t(job.found.loops.size()) != 2 * job.out.genus)
      throw std::logic_error(component_name(job.k, job.check) + ": wrong number of loops");
    result.seconds_verify += seconds_since(start);
    return classes;
  }

  // Shortens each loop (checking that it keeps its class and gets no longer) and hands the
  // loops out in the caller's vertex ids.
  void shorten_loops(ComponentJob& job, const SurfaceHomology& homology, const std::vector<Z2Vector>& classes) {
    const ClosedSurface& fine = job.fine;
    const auto& loops = job.found.loops;
    ComponentLoops& out = job.out;
    auto start = Clock::now();
    progress.stage("shorten", job.at(0.7), job.at(1.0));
    std::vector<std::vector<int32_t>> shortened = loops;
    if (params.shorten) {
      TightenParams moves;  // loops carried back from a tightened coarse loop need small moves only
      if (out.route == "coarse") moves.max_window = 64;
      tighten_loops(fine, job.fine_weight, &homology, shortened, moves, &progress);
      result.seconds_shorten += seconds_since(start);
      start = Clock::now();
      check_shortened(job, homology, classes, shortened);
      result.seconds_verify += seconds_since(start);
    }
    const std::vector<double> euclidean = params.count_edges ? edge_weights(fine, false) : job.fine_weight;
    auto to_caller = [&](int32_t v) { return mesh.vertex_source()[fine.mesh_vertex[v]]; };
    for (size_t i = 0; i < loops.size(); ++i) {
      HandleTunnelLoop loop;
      loop.handle = job.found.is_handle[i];
      loop.initial_length = loop_length(fine, loops[i], euclidean);
      for (int32_t v : loops[i]) loop.initial_vertices.push_back(to_caller(v));
      loop.length = loop_length(fine, shortened[i], euclidean);
      for (int32_t v : shortened[i]) loop.vertices.push_back(to_caller(v));
      loop.generator[0] = to_caller(job.found.generators[i].first);
      loop.generator[1] = to_caller(job.found.generators[i].second);
      (loop.handle ? out.handles : out.tunnels).push_back(std::move(loop));
    }
    if (int32_t(out.handles.size()) != out.genus || int32_t(out.tunnels.size()) != out.genus)
      throw std::logic_error(component_name(job.k, job.check) + ": expected " + std::to_string(out.genus) +
                             " loops of each kind");
  }

  // Each shortened loop is simple, keeps its class and is no longer than before (on the team:
  // the checks are independent).
  void check_shortened(const ComponentJob& job, const SurfaceHomology& homology, const std::vector<Z2Vector>& classes,
                       const std::vector<std::vector<int32_t>>& shortened) {
    const ClosedSurface& fine = job.fine;
    const auto& loops = job.found.loops;
    parallel_region(loops.size() >= 2 ? max_threads() : 1, [&](Team& team) {
      std::vector<uint8_t> seen(fine.num_vertices(), 0);
      team.for_static(0, int64_t(loops.size()), [&](int64_t i) {
        check_simple(fine, shortened[i], seen);
        if (!(homology.class_of_loop(fine, shortened[i]) == classes[i]) ||
            homology.integer_class_of_loop(fine, shortened[i]) != homology.integer_class_of_loop(fine, loops[i]))
          throw std::logic_error(component_name(job.k, job.check) + ": shortening changed a loop's class");
        if (loop_length(fine, shortened[i], job.fine_weight) > loop_length(fine, loops[i], job.fine_weight) * (1 + 1e-12))
          throw std::logic_error(component_name(job.k, job.check) + ": shortening made a loop longer");
      });
    });
  }
};

}  // namespace

LoopsResult compute_loops(const Mesh& mesh, const LoopParams& params) { return LoopsComputation(mesh, params).run(); }

std::vector<int32_t> shorten_loop(const Mesh& mesh, const std::vector<int32_t>& loop, const LoopParams& params,
                                  int32_t max_window) {
  if (loop.size() < 3) throw std::invalid_argument("a loop needs at least three vertices");
  std::vector<int32_t> internal;
  for (size_t i = 0; i < loop.size(); ++i) {
    if (loop[i] < 0 || loop[i] >= int32_t(mesh.vertex_index().size()))
      throw std::invalid_argument("loop vertex " + std::to_string(i) + " is " + std::to_string(loop[i]) +
                                  ", outside [0, " + std::to_string(mesh.vertex_index().size()) + ")");
    internal.push_back(mesh.vertex_index()[loop[i]]);
  }
  const int32_t component = mesh.component()[internal[0]];
  if (component < 0) throw std::invalid_argument("loop vertex 0 is in no triangle");
  const auto components = component_vertices(mesh);
  const auto checks = check_closed_surfaces(mesh, components);
  if (!checks[component].problem.empty())
    throw std::invalid_argument("the loop lies on a component that is " + checks[component].problem + " (" +
                                checks[component].detail + "); loops are shortened on closed manifold surfaces");
  const ClosedSurface s = extract_surface(mesh, components[component]);
  std::vector<int32_t> local;
  for (size_t i = 0; i < internal.size(); ++i) {
    local.push_back(local_id(components[component], internal[i]));
    if (local.back() < 0) throw std::invalid_argument("the loop leaves the component of its first vertex");
  }
  std::vector<uint8_t> seen(s.num_vertices(), 0);
  for (size_t i = 0; i < local.size(); ++i) {
    if (seen[local[i]]) throw std::invalid_argument("the loop visits vertex " + std::to_string(loop[i]) + " twice");
    seen[local[i]] = 1;
    if (s.find_edge(local[i], local[(i + 1) % local.size()]) < 0)
      throw std::invalid_argument("loop vertices " + std::to_string(loop[i]) + " and " +
                                  std::to_string(loop[(i + 1) % loop.size()]) + " are not joined by an edge");
  }
  const auto weight = edge_weights(s, params.count_edges);
  const SurfaceHomology homology(s);
  LoopTightener tightener(s, weight, &homology);
  TightenParams tighten;
  tighten.max_window = max_window;
  Progress progress(params.progress);
  const auto shortened = tightener.tighten(local, tighten, &progress);
  if (homology.integer_class_of_loop(s, shortened) != homology.integer_class_of_loop(s, local))
    throw std::logic_error("shortening changed the loop's class");
  std::vector<int32_t> out;
  for (int32_t v : shortened) out.push_back(mesh.vertex_source()[s.mesh_vertex[v]]);
  return out;
}

}  // namespace topstoc
