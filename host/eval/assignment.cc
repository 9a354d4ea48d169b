#include "host/eval/assignment.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace litgs::host {

Assignment min_cost_assignment(size_t n, const std::function<double(size_t, size_t)>& cost_fn) {
  // The matrix is read once into memory: the augmenting-path loop visits each entry many times.
  std::vector<double> cost(n * n);
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < n; ++j) {
      const double c = cost_fn(i, j);
      if (!std::isfinite(c))
        throw std::invalid_argument("min_cost_assignment: cost(" + std::to_string(i) + ", " +
                                    std::to_string(j) + ") is not finite");
      cost[i * n + j] = c;
    }
  // Rows and columns are numbered from 1; column 0 is a virtual column that holds the row being inserted.
  // Invariant: u[i] + v[j] <= cost(i, j) for all pairs, with equality on the matched pairs (reduced costs are
  // non-negative), so the matching is optimal once it is perfect.
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> u(n + 1, 0.0), v(n + 1, 0.0), min_reduced(n + 1);
  std::vector<size_t> row_of_column(n + 1, 0), previous_column(n + 1, 0);
  std::vector<char> visited(n + 1);
  for (size_t row = 1; row <= n; ++row) {
    row_of_column[0] = row;
    size_t column = 0;
    std::fill(min_reduced.begin(), min_reduced.end(), inf);
    std::fill(visited.begin(), visited.end(), 0);
    // Dijkstra over reduced costs from the new row until a free column is reached.
    do {
      visited[column] = 1;
      const size_t i = row_of_column[column];
      double delta = inf;
      size_t next = 0;
      for (size_t j = 1; j <= n; ++j) {
        if (visited[j]) continue;
        const double reduced = cost[(i - 1) * n + (j - 1)] - u[i] - v[j];
        if (reduced < min_reduced[j]) {
          min_reduced[j] = reduced;
          previous_column[j] = column;
        }
        if (min_reduced[j] < delta) {
          delta = min_reduced[j];
          next = j;
        }
      }
      for (size_t j = 0; j <= n; ++j) {
        if (visited[j]) {
          u[row_of_column[j]] += delta;
          v[j] -= delta;
        } else {
          min_reduced[j] -= delta;
        }
      }
      column = next;
    } while (row_of_column[column] != 0);
    // Flip the matching along the path back to the virtual column.
    do {
      const size_t back = previous_column[column];
      row_of_column[column] = row_of_column[back];
      column = back;
    } while (column != 0);
  }
  Assignment a;
  a.column_of_row.assign(n, 0);
  for (size_t j = 1; j <= n; ++j) a.column_of_row[row_of_column[j] - 1] = j - 1;
  for (size_t i = 0; i < n; ++i) a.total_cost += cost[i * n + a.column_of_row[i]];
  return a;
}

}  // namespace litgs::host
