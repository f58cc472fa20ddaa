// bbm fem: the sparse linear solve behind the implicit elastic stage (SPEC §5).
//
// The stiffness of an elastic block model (rigid blocks, FE nodes, joints) is
// symmetric and, once the supports remove every rigid-body mode, positive
// definite: CHOLMOD's simplicial Cholesky factorises it (through Eigen's
// wrapper; simplicial because it does not call the BLAS, so the answer is the
// same bits whichever BLAS the machine has). If Cholesky fails — an indefinite matrix, e.g. from joints in
// compression with large geometric terms — a sparse LU (Eigen) is tried; if the
// residual still fails (coefficients over many decades: a flow network from
// intact bonds to parted blocks), both again on the system scaled by its
// diagonal. A
// singular system (a floating block, a model without supports) cannot be solved
// either way; the caller gets the residual so it can say so.
#pragma once

#include <string>
#include <vector>

namespace bbm::fem {

/// A square sparse matrix as triplets; duplicates are summed. Both triangles given.
struct SparseTriplets {
    int size = 0;
    std::vector<int> row, col;
    std::vector<double> value;
    void add(int r, int c, double v) {
        row.push_back(r);
        col.push_back(c);
        value.push_back(v);
    }
};

struct SolveReport {
    std::string method;           ///< "cholmod-simplicial-cholesky" or "sparse-lu", ", diagonally scaled" if it was
    double relative_residual = 0; ///< |K x − f| / |f| (of the scaled system if it was)
};

/// Solves K x = f. Throws std::runtime_error with the reason if no factorisation
/// succeeds or the residual shows the system is singular.
std::vector<double> solve_sparse(const SparseTriplets& k, const std::vector<double>& f, SolveReport* report = nullptr);

} // namespace bbm::fem
