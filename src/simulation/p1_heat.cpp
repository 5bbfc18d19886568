// P1 heat step: assembly into a compressed sparse row matrix, Jacobi-preconditioned CG, and the
// residual estimator η_T² = h_T² ||f - (u - u_old)/dt||²_T + 1/2 Σ_{E ⊂ ∂T interior} h_E ||[∂u/∂n]||²_E
// (Δu = 0 inside a P1 element).
#include "simulation/p1_heat.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_map>

namespace amc {

namespace {

struct Csr {
    std::vector<uint32_t> row_start, col;
    std::vector<double> val;
    size_t rows() const { return row_start.size() - 1; }
};

// Gradients of the three barycentric functions of triangle (a, b, c) in the plane, and its area.
double p1_gradients(Vec3 a, Vec3 b, Vec3 c, double gx[3], double gy[3]) {
    const double area2 = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
    const Vec3 p[3] = {a, b, c};
    for (int i = 0; i < 3; ++i) {
        const Vec3 q = p[(i + 1) % 3], r = p[(i + 2) % 3];
        gx[i] = (q.y - r.y) / area2;
        gy[i] = (r.x - q.x) / area2;
    }
    return 0.5 * std::fabs(area2);
}

uint64_t edge_key(uint32_t a, uint32_t b) { return a < b ? (uint64_t(a) << 32) | b : (uint64_t(b) << 32) | a; }

// Rows with the sparsity of the mesh (diagonal included), columns sorted.
Csr mesh_pattern(const TriangleMesh& mesh) {
    const size_t n = mesh.positions.size();
    std::vector<std::vector<uint32_t>> adj(n);
    for (const Triangle& t : mesh.triangles)
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) adj[t[size_t(i)]].push_back(t[size_t(j)]);
    Csr m;
    m.row_start.assign(n + 1, 0);
    for (size_t i = 0; i < n; ++i) {
        std::sort(adj[i].begin(), adj[i].end());
        adj[i].erase(std::unique(adj[i].begin(), adj[i].end()), adj[i].end());
        if (adj[i].empty()) adj[i].push_back(uint32_t(i));
        m.row_start[i + 1] = m.row_start[i] + uint32_t(adj[i].size());
    }
    m.col.reserve(m.row_start[n]);
    for (size_t i = 0; i < n; ++i) m.col.insert(m.col.end(), adj[i].begin(), adj[i].end());
    m.val.assign(m.col.size(), 0.0);
    return m;
}

double& entry(Csr& m, uint32_t i, uint32_t j) {
    auto begin = m.col.begin() + m.row_start[i], end = m.col.begin() + m.row_start[i + 1];
    return m.val[size_t(std::lower_bound(begin, end, j) - m.col.begin())];
}

void multiply(const Csr& m, const std::vector<double>& x, std::vector<double>& y) {
    for (size_t i = 0; i < m.rows(); ++i) {
        double s = 0;
        for (uint32_t k = m.row_start[i]; k < m.row_start[i + 1]; ++k) s += m.val[k] * x[m.col[k]];
        y[i] = s;
    }
}

double dot(const std::vector<double>& a, const std::vector<double>& b) {
    double s = 0;
    for (size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
    return s;
}

uint32_t conjugate_gradients(const Csr& a, const std::vector<double>& b, std::vector<double>& x) {
    const size_t n = b.size();
    std::vector<double> inv_diag(n), r(n), z(n), p(n), q(n);
    for (size_t i = 0; i < n; ++i) inv_diag[i] = 1.0 / entry(const_cast<Csr&>(a), uint32_t(i), uint32_t(i));
    multiply(a, x, q);
    for (size_t i = 0; i < n; ++i) r[i] = b[i] - q[i];
    const double b_norm = std::sqrt(dot(b, b));
    if (b_norm == 0) {
        std::fill(x.begin(), x.end(), 0.0);
        return 0;
    }
    for (size_t i = 0; i < n; ++i) z[i] = inv_diag[i] * r[i];
    p = z;
    double rz = dot(r, z);
    uint32_t it = 0;
    for (; it < 10000 && std::sqrt(dot(r, r)) > 1e-8 * b_norm; ++it) {
        multiply(a, p, q);
        const double alpha = rz / dot(p, q);
        for (size_t i = 0; i < n; ++i) {
            x[i] += alpha * p[i];
            r[i] -= alpha * q[i];
        }
        for (size_t i = 0; i < n; ++i) z[i] = inv_diag[i] * r[i];
        const double rz_new = dot(r, z);
        const double beta = rz_new / rz;
        rz = rz_new;
        for (size_t i = 0; i < n; ++i) p[i] = z[i] + beta * p[i];
    }
    return it;
}

}  // namespace

HeatStepResult heat_step(const TriangleMesh& mesh, const std::vector<double>& u_old, const std::vector<double>& f,
                         double dt) {
    const size_t n = mesh.positions.size(), nt = mesh.triangles.size();
    // Edges: the triangles on each side, to find the boundary and the flux jumps.
    std::unordered_map<uint64_t, std::array<uint32_t, 2>> edges;
    edges.reserve(nt * 2);
    for (uint32_t t = 0; t < nt; ++t)
        for (int i = 0; i < 3; ++i) {
            auto it = edges.try_emplace(edge_key(mesh.triangles[t][size_t(i)], mesh.triangles[t][size_t((i + 1) % 3)]),
                                        std::array<uint32_t, 2>{t, UINT32_MAX});
            if (!it.second) it.first->second[1] = t;
        }
    std::vector<uint8_t> boundary(n, 0);
    for (const auto& [key, sides] : edges)
        if (sides[1] == UINT32_MAX) boundary[key >> 32] = boundary[key & 0xffffffffu] = 1;

    Csr a = mesh_pattern(mesh);
    std::vector<double> lumped(n, 0.0);
    std::vector<double> gx(nt * 3), gy(nt * 3), area(nt);
    for (uint32_t t = 0; t < nt; ++t) {
        const Triangle& tri = mesh.triangles[t];
        area[t] = p1_gradients(mesh.positions[tri[0]], mesh.positions[tri[1]], mesh.positions[tri[2]], &gx[3 * t],
                               &gy[3 * t]);
        for (int i = 0; i < 3; ++i) {
            lumped[tri[size_t(i)]] += area[t] / 3;
            for (int j = 0; j < 3; ++j)
                entry(a, tri[size_t(i)], tri[size_t(j)]) +=
                    dt * area[t] * (gx[3 * t + i] * gx[3 * t + j] + gy[3 * t + i] * gy[3 * t + j]);
        }
    }
    std::vector<double> rhs(n);
    for (uint32_t i = 0; i < n; ++i) {
        entry(a, i, i) += lumped[i];
        rhs[i] = lumped[i] * (u_old[i] + dt * f[i]);
    }
    // u = 0 on the boundary: identity rows, and the columns dropped (their values are 0).
    for (uint32_t i = 0; i < n; ++i) {
        for (uint32_t k = a.row_start[i]; k < a.row_start[i + 1]; ++k) {
            if (boundary[i] || boundary[a.col[k]]) a.val[k] = (a.col[k] == i) ? 1.0 : 0.0;
        }
        if (boundary[i]) rhs[i] = 0;
    }

    HeatStepResult out;
    out.u = u_old;
    for (uint32_t i = 0; i < n; ++i)
        if (boundary[i]) out.u[i] = 0;
    out.cg_iterations = conjugate_gradients(a, rhs, out.u);

    // Estimator.
    out.gradient.resize(nt);
    out.indicator.assign(nt, 0.0);
    for (uint32_t t = 0; t < nt; ++t) {
        const Triangle& tri = mesh.triangles[t];
        double ux = 0, uy = 0, residual = 0, h2 = 0;
        for (int i = 0; i < 3; ++i) {
            const uint32_t v = tri[size_t(i)];
            ux += out.u[v] * gx[3 * t + i];
            uy += out.u[v] * gy[3 * t + i];
            residual += (f[v] - (out.u[v] - u_old[v]) / dt) / 3;
            const Vec3 e = mesh.positions[tri[size_t((i + 1) % 3)]] - mesh.positions[v];
            h2 = std::max(h2, dot(e, e));
        }
        out.gradient[t] = {ux, uy, 0.0};
        out.indicator[t] = h2 * area[t] * residual * residual;
    }
    for (const auto& [key, sides] : edges) {
        if (sides[1] == UINT32_MAX) continue;
        const Vec3 e = mesh.positions[key & 0xffffffffu] - mesh.positions[key >> 32];
        const Vec3 jump = out.gradient[sides[0]] - out.gradient[sides[1]];
        const double jn = jump.x * e.y - jump.y * e.x;  // |E| · [∇u · n]
        const double share = 0.5 * jn * jn;             // h_E |E| [∂u/∂n]², halved per side
        out.indicator[sides[0]] += share;
        out.indicator[sides[1]] += share;
    }
    for (double& eta : out.indicator) eta = std::sqrt(eta);
    return out;
}

}  // namespace amc
