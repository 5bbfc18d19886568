// One implicit Euler step of the heat equation with P1 elements on a planar triangle mesh, and
// the residual error estimator (Verfürth, "A Posteriori Error Estimation Techniques", ch. 1):
//   (M + dt K) u = M u_old + dt M f,   u = 0 on the boundary,
// with the lumped mass matrix M, the stiffness matrix K, solved by conjugate gradients with a
// Jacobi preconditioner (the matrix is symmetric positive definite).
#pragma once

#include <amc/mesh.h>

#include <cstdint>
#include <vector>

namespace amc {

struct HeatStepResult {
    std::vector<double> u;            // at the vertices
    std::vector<double> indicator;    // η_T per triangle
    std::vector<Vec3> gradient;       // ∇u per triangle
    uint32_t cg_iterations = 0;
};

// `f` holds the source at the vertices (lumped: ∫ f φ_i ≈ f_i M_ii). `u_old` is the start of the
// CG iteration too.
HeatStepResult heat_step(const TriangleMesh& mesh, const std::vector<double>& u_old, const std::vector<double>& f,
                         double dt);

}  // namespace amc
