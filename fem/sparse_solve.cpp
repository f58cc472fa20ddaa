#include "fem/sparse_solve.hpp"

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>

#include <cmath>
#include <stdexcept>

namespace bbm::fem {

namespace {

using Matrix = Eigen::SparseMatrix<double>;

struct Attempt {
    Eigen::VectorXd x;
    std::string method;
    double residual = INFINITY; ///< |m x − rhs| / |rhs|
    std::string failure;        ///< why no factorisation succeeded, if none did
};

/// Cholesky, and a sparse LU if Cholesky fails or leaves a residual over 1e-8.
Attempt factor_and_solve(const Matrix& m, const Eigen::VectorXd& rhs) {
    Attempt a;
    // Simplicial, not supernodal: the supernodal factorisation calls the BLAS, and
    // the BLAS installed (reference, OpenBLAS with its per-CPU kernels) changes the
    // last bits of the answer, which a failing model turns into other cracks.
    Eigen::CholmodSimplicialLLT<Matrix, Eigen::Lower> chol;
    chol.cholmod().print = 0; // a matrix that is not positive definite falls back to LU below, quietly
    chol.compute(m);
    if (chol.info() == Eigen::Success) {
        a.x = chol.solve(rhs);
        a.method = "cholmod-simplicial-cholesky";
    }
    const double fnorm = rhs.norm() > 0 ? rhs.norm() : 1.0;
    auto residual = [&] { return a.x.allFinite() ? (m * a.x - rhs).norm() / fnorm : INFINITY; };
    if (a.method.empty() || residual() > 1e-8) {
        Eigen::SparseLU<Matrix> lu;
        lu.analyzePattern(m);
        lu.factorize(m);
        if (lu.info() != Eigen::Success) {
            a.failure = lu.lastErrorMessage();
            return a;
        }
        a.x = lu.solve(rhs);
        a.method = "sparse-lu";
    }
    a.residual = residual();
    return a;
}

} // namespace

std::vector<double> solve_sparse(const SparseTriplets& k, const std::vector<double>& f, SolveReport* report) {
    std::vector<Eigen::Triplet<double>> t;
    t.reserve(k.value.size());
    for (std::size_t i = 0; i < k.value.size(); ++i) t.emplace_back(k.row[i], k.col[i], k.value[i]);
    Matrix m(k.size, k.size);
    m.setFromTriplets(t.begin(), t.end());
    const Eigen::Map<const Eigen::VectorXd> rhs(f.data(), Eigen::Index(f.size()));
    Attempt a = factor_and_solve(m, rhs);
    if (!(a.residual < 1e-6)) {
        // Coefficients over many decades (a flow network whose joints range from
        // intact bonds to parted blocks: 15 decades of conductance) defeat the
        // unscaled solve. Scaled symmetrically by its diagonal, S K S y = S f with
        // x = S y, each row is of order one; S_ii are powers of two, so the scaling
        // itself is exact. Only when the plain solve failed: a solve that passed
        // keeps its bits.
        Eigen::VectorXd s = Eigen::VectorXd::Ones(k.size);
        const Eigen::VectorXd diagonal = m.diagonal();
        for (Eigen::Index i = 0; i < s.size(); ++i)
            if (diagonal[i] > 0 && std::isfinite(diagonal[i])) s[i] = std::ldexp(1.0, -std::ilogb(diagonal[i]) / 2);
        const Matrix scaled = s.asDiagonal() * m * s.asDiagonal();
        Attempt b = factor_and_solve(scaled, s.cwiseProduct(rhs));
        if (b.residual < 1e-6) {
            a = b;
            a.x = s.cwiseProduct(b.x);
            a.method += ", diagonally scaled";
        } else if (a.failure.empty()) {
            a.failure = b.failure;
        }
    }
    if (!a.failure.empty() && a.method.empty()) throw std::runtime_error("the stiffness matrix is singular (" + a.failure + ")");
    if (!(a.residual < 1e-6))
        throw std::runtime_error("the stiffness matrix is singular or nearly so (relative residual " +
                                 std::to_string(a.residual) + ")");
    if (report) *report = {a.method, a.residual};
    return {a.x.data(), a.x.data() + a.x.size()};
}

} // namespace bbm::fem
