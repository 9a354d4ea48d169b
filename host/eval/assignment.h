// Exact minimum-cost assignment (the linear assignment problem) for a square cost matrix: the Hungarian
// method with row and column potentials and shortest augmenting paths, O(n^3) time, O(n) extra memory.
// The earth mover's distance between two equal-sized point sets with equal masses is such an assignment
// (the transportation polytope's vertices are permutations, Birkhoff-von Neumann), so this solves it exactly.
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

namespace litgs::host {

struct Assignment {
  std::vector<size_t> column_of_row;  // [n]: the column assigned to each row (a permutation)
  double total_cost = 0;              // sum of cost(row, column_of_row[row])
};

// `cost(i, j)`, i, j < n, must be finite (std::invalid_argument naming the first entry that is not). n = 0
// gives an empty assignment of cost 0.
Assignment min_cost_assignment(size_t n, const std::function<double(size_t, size_t)>& cost);

}  // namespace litgs::host
