#include "fem/sparse_solve.hpp"

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>

#include <stdexcept>

namespace bbm::fem {

std::vector<double> solve_sparse(const SparseTriplets& k, const std::vector<double>& f, SolveReport* report) {
    using Matrix = Eigen::SparseMatrix<double>;
    std::vector<Eigen::Triplet<double>> t;
    t.reserve(k.value.size());
    for (std::size_t i = 0; i < k.value.size(); ++i) t.emplace_back(k.row[i], k.col[i], k.value[i]);
    Matrix m(k.size, k.size);
    m.setFromTriplets(t.begin(), t.end());
    const Eigen::Map<const Eigen::VectorXd> rhs(f.data(), Eigen::Index(f.size()));
    Eigen::VectorXd x;
    std::string method;
    // Simplicial, not supernodal: the supernodal factorisation calls the BLAS, and
    // the BLAS installed (reference, OpenBLAS with its per-CPU kernels) changes the
    // last bits of the answer, which a failing model turns into other cracks.
    Eigen::CholmodSimplicialLLT<Matrix, Eigen::Lower> chol;
    chol.cholmod().print = 0; // a matrix that is not positive definite falls back to LU below, quietly
    chol.compute(m);
    if (chol.info() == Eigen::Success) {
        x = chol.solve(rhs);
        method = "cholmod-simplicial-cholesky";
    }
    const double fnorm = rhs.norm() > 0 ? rhs.norm() : 1.0;
    auto residual = [&] { return (m * x - rhs).norm() / fnorm; };
    if (method.empty() || !x.allFinite() || residual() > 1e-8) {
        Eigen::SparseLU<Matrix> lu;
        lu.analyzePattern(m);
        lu.factorize(m);
        if (lu.info() != Eigen::Success)
            throw std::runtime_error("the stiffness matrix is singular (" + lu.lastErrorMessage() + ")");
        x = lu.solve(rhs);
        method = "sparse-lu";
    }
    const double r = x.allFinite() ? residual() : INFINITY;
    if (!(r < 1e-6))
        throw std::runtime_error("the stiffness matrix is singular or nearly so (relative residual " +
                                 std::to_string(r) + ")");
    if (report) *report = {method, r};
    return {x.data(), x.data() + x.size()};
}

} // namespace bbm::fem
