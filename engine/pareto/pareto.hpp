#pragma once
// Pareto fronts of 2 or 3 objectives and their hypervolume indicator.
//
// Points are rows of a row-major array: point i is values[i * dims + 0 .. dims - 1], dims = 2 or 3.
// Each objective has a sense: minimised or maximised. Point a dominates point b when a is at least
// as good as b in every objective and strictly better in one; equal points do not dominate each
// other (duplicates of a front point are all on the front). A point with a NaN coordinate is never
// on a front and adds no volume.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace ks::pareto {

enum class Sense { min, max };

/// The indices (ascending) of the non-dominated points among the n = values.size() / dims points
/// that hold no NaN and are eligible (`eligible` empty: all; else point i when eligible[i] != 0, e.g.
/// the runs of a good status): the others neither are on the front nor dominate. Sort-based: O(n log n) for 2 objectives; for 3, a lexicographic sort and a test
/// of each point against the front so far, O(n log n + n f) with f the front's size.
/// `senses.size()` must be `dims` (2 or 3) and `eligible` empty or of n flags; throws
/// std::invalid_argument otherwise.
std::vector<std::size_t> front(std::span<const double> values, std::size_t dims, std::span<const Sense> senses,
                               std::span<const std::uint8_t> eligible = {});

/// Whether `a` dominates `b` (both of senses.size() coordinates) in the senses given.
bool dominates(std::span<const double> a, std::span<const double> b, std::span<const Sense> senses);

/// The hypervolume indicator of the points (any set: dominated points add nothing) against the
/// reference point `ref`: the measure of the region of objective space that some point dominates
/// (weakly) and that dominates `ref`, i.e. the union over points p of the boxes between p and ref.
/// A point not strictly better than ref in every objective adds nothing; NaN points are skipped.
/// In the objectives' units multiplied (an area for 2 objectives, a volume for 3). Exact: a sweep
/// in 2-D (O(n log n)), slices along the third objective in 3-D (O(n² log n)).
/// Throws std::invalid_argument when ref.size() or senses.size() is not dims (2 or 3), or ref holds NaN.
double hypervolume(std::span<const double> values, std::size_t dims, std::span<const Sense> senses,
                   std::span<const double> ref);

}  // namespace ks::pareto
