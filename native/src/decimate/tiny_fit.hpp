// The fit (docs/design.md §2.10): once the collapses reached their result, its free vertices are
// fitted to the input in a few rounds of least squares, both ways (as Hoppe et al. 1993 fit a
// mesh to points): the quadrics that placed them sum planes over clusters too large to stand for
// the surface. Results above kFitFaces triangles get one round with a cheaper max check.
#pragma once

#include <cstdint>
#include <vector>

#include "decimate/collapser.hpp"
#include "topstoc/core/mesh.hpp"
#include "topstoc/distance/hausdorff.hpp"

namespace topstoc {

/// Results with at most this many live triangles are fitted in up to four rounds, and results
/// with more in one (its first round gives most of the gain; a round's max check costs more
/// than the collapses there), their mesh boundaries kept where they are; above kFitFaces the
/// max is not bracketed before the move (fit_tiny's known_max).
constexpr int32_t kTinyFitFaces = 400;
constexpr int32_t kFitFaces = 1400;

/// Rounds of the fit for a result of `live_faces` triangles: larger results get one, judged
/// against a max the caller knows (fit_tiny's known_max).
inline int32_t fit_rounds(int64_t live_faces) { return live_faces <= kTinyFitFaces ? 4 : 1; }

struct TinyFit {
  int32_t rounds = 0;        ///< rounds kept (each lowered the error)
  double before2 = 0.0;      ///< mean squared distance, both ways, before the first round
  double after2 = 0.0;       ///< and after the last kept one
  int64_t queries = 0;       ///< closest-point queries of its brackets (kTestedPerQuery triangles measured count as one)
  int32_t brackets = 0;      ///< brackets of the symmetric max it measured (each two sides)
};

/// The step between the input triangles the fit measures against (1: all of them): at most
/// 200,000 are taken, evenly (deviation.hpp's normalised_input with this step is `input` below).
int64_t fit_input_step(const Mesh& mesh);

/// Rounds (at most `rounds`) of: pair input vertices (at most 20,000, evenly taken) with their
/// closest point on the result and 7 points of each result triangle with their closest point
/// on `input` (the input's triangles every fit_input_step, in the collapser's normalised
/// coordinates, made by the caller so that it may be kept for later decimations); move the free and boundary
/// vertices to the least-squares fit of those pairs, each only where no triangle folds or thins
/// (Collapser::try_move); keep a round only if the mean squared distance fell, the largest pair
/// distance did not grow, and neither did the symmetric Hausdorff max over both whole surfaces
/// (a bracket from bounded_max.hpp: the pairs alone miss where the surface lifts between them).
/// boundaries: the unlocked vertices of mesh boundaries move too (else only the free ones).
/// Results above kFitFaces are fitted only with known_max > 0, a distance between the result and
/// `input` (the whole input there) that the symmetric max attains: their one round is solved by
/// conjugate gradients and kept only when a threshold walk a side finds no point farther than it
/// (the max does not grow), holding the corners where one does; their after2 is not measured
/// again (it stays before2).
TinyFit fit_tiny(const Mesh& mesh, Collapser& collapser, int32_t rounds, bool boundaries, const Surface& input,
                 double known_max = -1.0);

}  // namespace topstoc
