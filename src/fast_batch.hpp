// Copyright 2026 grasp_torque_opt developers
//
// Use of this source code is governed by a BSD-style
// license that can be found in the LICENSE file or at
// https://developers.google.com/open-source/licenses/bsd
//
// SPDX-License-Identifier: BSD-3-Clause

// Batch scoring's compiled stages (grasp_torque_opt.methods.batch): the maps and build
// stages of fast_cycle.hpp for many candidates of one hand in one call, with each
// tau-QP written in DAQP's form, and after the DAQP solves the KKT check, the wrenches,
// the certificate and the planner's numbers of every answer in one call. Included by
// fast_cycle.hpp after FastCycle; the same rules, nothing of its own.

#ifndef FAST_BATCH_HPP_
#define FAST_BATCH_HPP_

#include <Eigen/Geometry>
#include <Eigen/QR>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

#include "vertex_lp.hpp"

namespace
{

py::array_t<double> zeros(std::vector<py::ssize_t> shape)
{
  py::array_t<double> out(shape);
  std::fill(out.mutable_data(), out.mutable_data() + out.size(), 0.0);
  return out;
}


// The build stage of FastCycle::build (core/tau_qp.build_tau_qp, the QR branch) for the
// batch, with no torque offset, computing only what the batch needs and reusing its
// storage: with A = [G; J^T] = Q [R; 0], Q^T applied once to [[0, w]; [I_m, 0]] gives
// Q1^T and U_perp^T on those columns, so M2 = R^-1 (Q1^T [0; I_m]), M1 w = R^-1 (Q1^T [w; 0]),
// A_eq = U_perp[6:]^T and b = -U_perp[:6]^T w without forming Q or pinv(A).
struct LeanBuild
{
  Mat A_full, T, X;
  Eigen::HouseholderQR<Mat> qr;
  RowMat C;
  Vec u;

  // false and why where FastCycle::build hands back (not of full column rank, not finite).
  bool run(
    const FastCycle & fc, const RowMat & G, const RowMat & J, const Wrench & w_ext,
    std::string & why)
  {
    const int m = fc.m(), cols = static_cast<int>(G.cols()), p = cols / 4, rows = 6 + m;
    if (rows < cols) {
      why = "A = [G; J^T] has more columns than rows";
      return false;
    }
    A_full.resize(rows, cols);
    A_full.topRows(6) = G;
    A_full.bottomRows(m) = J.transpose();
    if (!A_full.allFinite()) {
      why = "maps not finite";
      return false;
    }
    qr.compute(A_full);
    const Mat & packed = qr.matrixQR();
    const Vec d = packed.diagonal().head(cols).cwiseAbs();
    if (!(d.minCoeff() > fc.settings().qr_rtol * d.maxCoeff())) {
      why = "A = [G; J^T] is not of full column rank";
      return false;
    }
    T.setZero(rows, m + 1);
    T.bottomLeftCorner(m, m).setIdentity();
    T.col(m).head<6>() = -w_ext;  // w
    T.applyOnTheLeft(qr.householderQ().adjoint());
    X = packed.topRows(cols).triangularView<Eigen::Upper>().solve(T.topRows(cols));
    const RowMat & S = fc.S_i();
    const int block = static_cast<int>(S.rows());
    C.resize(block * p, m);
    u.resize(block * p);
    for (int i = 0; i < p; ++i) {
      C.middleRows(block * i, block) = S * X.block(4 * i, 0, 4, m);
      u.segment(block * i, block) = fc.b_i() - S * X.col(m).segment<4>(4 * i);
    }
    return true;
  }
  auto M2() const {return X.leftCols(X.cols() - 1);}
  auto M1w() const {return X.col(X.cols() - 1);}
  auto A_eq() const {return T.bottomLeftCorner(T.rows() - X.rows(), T.cols() - 1);}
  auto b_neg() const {return T.bottomRightCorner(T.rows() - X.rows(), 1);}  // -b
};

// The maps and build stages for N candidates with p contacts each. oMf (N, p, 4, 4),
// J6 (N, p, 6, nv), points, normals, tangents (N, p, 3), has_normal, has_tangent (N, p),
// c (3: one object origin for all, or N, 3: each candidate's),
// w_ext (N, 6). Returns a dict: ok (N) and why (N strings: '' where ok), and for
// each candidate G (6, 4p), J (4p, m), M1w = M1 w (4p), M2 (4p, m), positions (p, 3),
// rotations (p, 3, 3), and its tau-QP in DAQP's form (backends/daqp.DaqpSolver): A =
// [A_eq; C] (n_eq + n_in, m), bupper and blower (m + n_eq + n_in): the box (within
// DAQP_INF), the equalities, the cone rows. A candidate that is not ok (a frame that
// cannot be made, A = [G; J^T] not of full column rank) has zeros there.
py::dict build_batch(
  const FastCycle & fc, Array oMf, Array J6, Array points, Array normals,
  py::array_t<bool, py::array::c_style | py::array::forcecast> has_normal, Array tangents,
  py::array_t<bool, py::array::c_style | py::array::forcecast> has_tangent, Array c,
  Array w_ext)
{
  expect(oMf.ndim() == 4 && oMf.shape(2) == 4 && oMf.shape(3) == 4, "oMf of the wrong shape");
  const py::ssize_t N = oMf.shape(0), p = oMf.shape(1);
  expect(p > 0, "no contacts");
  expect(
    J6.ndim() == 4 && J6.shape(0) == N && J6.shape(1) == p && J6.shape(2) == 6,
    "J6 of the wrong shape");
  const py::ssize_t nv = J6.shape(3);
  for (const Array * a : {&points, &normals, &tangents}) {
    expect(
      a->ndim() == 3 && a->shape(0) == N && a->shape(1) == p && a->shape(2) == 3,
      "points, normals or tangents of the wrong shape");
  }
  expect(
    has_normal.size() == N * p && has_tangent.size() == N * p,
    "has_normal or has_tangent of the wrong shape");
  expect(c.size() == 3 || c.size() == 3 * N, "c of the wrong shape");
  const py::ssize_t c_step = c.size() == 3 ? 0 : 3;
  expect(
    w_ext.ndim() == 2 && w_ext.shape(0) == N && w_ext.shape(1) == 6,
    "w_ext of the wrong shape");
  const int m = fc.m();
  const py::ssize_t nf = 4 * p, rows = 6 + m;
  expect(rows >= nf, "A = [G; J^T] has more columns than rows");
  const py::ssize_t n_eq = rows - nf;
  const py::ssize_t n_in = static_cast<py::ssize_t>(fc.cone_rows()) * p;
  const py::ssize_t n_rows = n_eq + n_in, n_bounds = m + n_rows;
  py::array_t<bool> ok(N);
  std::vector<std::string> why(N);
  // Written for every candidate below (zeros where it is not ok): not filled first.
  using Out = py::array_t<double>;
  Out G({N, py::ssize_t(6), nf}), J({N, nf, py::ssize_t(m)}), M1w({N, nf});
  Out M2({N, nf, py::ssize_t(m)}), positions({N, p, py::ssize_t(3)});
  Out rotations({N, p, py::ssize_t(3), py::ssize_t(3)});
  Out A({N, n_rows, py::ssize_t(m)}), bupper({N, n_bounds}), blower({N, n_bounds});
  {
    py::gil_scoped_release release;
    Kinematics k;
    k.p = static_cast<int>(p);
    k.nv = static_cast<int>(nv);
    Maps maps;
    LeanBuild lean;
    const double box_margin = fc.settings().box_margin;
    for (py::ssize_t i = 0; i < N; ++i) {
      k.oMf = oMf.data() + 16 * p * i;
      k.J6 = J6.data() + 6 * nv * p * i;
      k.points = points.data() + 3 * p * i;
      k.normals = normals.data() + 3 * p * i;
      k.tangents = tangents.data() + 3 * p * i;
      k.has_normal = has_normal.data() + p * i;
      k.has_tangent = has_tangent.data() + p * i;
      k.c = Eigen::Map<const Eigen::Vector3d>(c.data() + c_step * i);
      const Wrench w = Eigen::Map<const Wrench>(w_ext.data() + 6 * i);
      bool good = fc.maps(k, maps, why[i]) && lean.run(fc, maps.G, maps.J, w, why[i]);
      if (good && lean.T.rows() - lean.X.rows() != n_eq) {
        why[i] = "A = [G; J^T] is not of full column rank";
        good = false;
      }
      ok.mutable_data()[i] = good;
      if (!good) {
        for (Out * a : {&G, &J, &M1w, &M2, &positions, &rotations, &A, &bupper, &blower}) {
          const py::ssize_t per = a->size() / N;
          std::fill(a->mutable_data() + per * i, a->mutable_data() + per * (i + 1), 0.0);
        }
        continue;
      }
      std::copy(maps.G.data(), maps.G.data() + maps.G.size(), G.mutable_data() + 6 * nf * i);
      std::copy(maps.J.data(), maps.J.data() + maps.J.size(), J.mutable_data() + nf * m * i);
      std::copy(
        maps.positions.data(), maps.positions.data() + maps.positions.size(),
        positions.mutable_data() + 3 * p * i);
      std::copy(
        maps.rotations.data(), maps.rotations.data() + maps.rotations.size(),
        rotations.mutable_data() + 9 * p * i);
      Eigen::Map<Vec>(M1w.mutable_data() + nf * i, nf) = lean.M1w();
      Eigen::Map<RowMat>(M2.mutable_data() + nf * m * i, nf, m) = lean.M2();
      Eigen::Map<RowMat> Ai(A.mutable_data() + n_rows * m * i, n_rows, m);
      Ai.topRows(n_eq) = lean.A_eq();
      Ai.bottomRows(n_in) = lean.C;
      double * up = bupper.mutable_data() + n_bounds * i;
      double * lo = blower.mutable_data() + n_bounds * i;
      for (int j = 0; j < m; ++j) {  // the box: tau_min, tau_max = -+limits, BOX_MARGIN in
        up[j] = std::min(fc.limits()(j) - box_margin, DAQP_INF);
        lo[j] = std::max(-fc.limits()(j) + box_margin, -DAQP_INF);
      }
      for (py::ssize_t j = 0; j < n_eq; ++j) {
        up[m + j] = lo[m + j] = -lean.b_neg()(j, 0);
      }
      for (py::ssize_t j = 0; j < n_in; ++j) {
        up[m + n_eq + j] = lean.u(j);
        lo[m + n_eq + j] = -DAQP_INF;
      }
    }
  }
  py::list why_list;
  for (const std::string & w : why) {
    why_list.append(w);
  }
  py::dict d;
  d["ok"] = ok;
  d["why"] = why_list;
  d["G"] = G;
  d["J"] = J;
  d["M1w"] = M1w;
  d["M2"] = M2;
  d["positions"] = positions;
  d["rotations"] = rotations;
  d["A"] = A;
  d["bupper"] = bupper;
  d["blower"] = blower;
  d["n_eq"] = n_eq;
  return d;
}

// After the DAQP solves: for each candidate with solved[i] (DAQP's exit flag 1), the KKT
// violation of x[i] with lam[i] (an answer over kkt_tolerance is not taken), the
// wrenches f = M1 w + M2 tau, the certificate against the exact problem, the friction
// usage (unreduced cone) and max |tau| / limit.
// Returns a dict: kkt (N; inf where not solved), certificate (N, 6: equilibrium,
// torque, cone, normal_force, limit, finite), passes (N: finite and every residual within
// the tolerance), f (N, 4p), usage (N, p), ratio (N).
py::dict finish_batch(
  const FastCycle & fc, Array G, Array J, Array w_ext, Array M1w, Array M2, Array A,
  Array bupper, Array blower, Array x, Array lam,
  py::array_t<bool, py::array::c_style | py::array::forcecast> solved, double kkt_tolerance)
{
  const int m = fc.m();
  expect(G.ndim() == 3 && G.shape(1) == 6, "G of the wrong shape");
  const py::ssize_t N = G.shape(0), nf = G.shape(2), p = nf / 4;
  expect(nf % 4 == 0 && nf > 0, "G of the wrong shape");
  expect(J.size() == N * nf * m && M2.size() == N * nf * m, "J or M2 of the wrong shape");
  expect(M1w.size() == N * nf && w_ext.size() == N * 6, "M1w or w_ext of the wrong shape");
  expect(A.ndim() == 3 && A.shape(0) == N && A.shape(2) == m, "A of the wrong shape");
  const int rows = static_cast<int>(A.shape(1));
  const py::ssize_t nb = m + rows;
  expect(
    bupper.size() == N * nb && blower.size() == N * nb && lam.size() == N * nb,
    "bupper, blower or lam of the wrong shape");
  expect(x.size() == N * m && solved.size() == N, "x or solved of the wrong shape");
  auto kkt = zeros({N}), cert = zeros({N, 6}), f = zeros({N, nf}), usage = zeros({N, p});
  auto ratio = zeros({N});
  py::array_t<bool> passes(N);
  const Vec tau_max = fc.limits(), tau_min = -fc.limits();
  const Vec hdiag = 2.0 * fc.weights();
  {
    py::gil_scoped_release release;
    const double inf = std::numeric_limits<double>::infinity();
    for (py::ssize_t i = 0; i < N; ++i) {
      bool good = solved.data()[i];
      double * ci = cert.mutable_data() + 6 * i;
      kkt.mutable_data()[i] = good ? daqp_kkt(
        hdiag, nullptr, A.data() + rows * m * i, bupper.data() + nb * i,
        blower.data() + nb * i, x.data() + m * i, lam.data() + nb * i, m, rows) : inf;
      good = good && kkt.data()[i] <= kkt_tolerance;
      if (!good) {
        std::fill(ci, ci + 5, inf);
        passes.mutable_data()[i] = false;
        continue;
      }
      const Vec tau = Eigen::Map<const Vec>(x.data() + m * i, m);
      Eigen::Map<Vec> fi(f.mutable_data() + nf * i, nf);
      fi = Eigen::Map<const Vec>(M1w.data() + nf * i, nf) +
        Eigen::Map<const RowMat>(M2.data() + nf * m * i, nf, m) * tau;
      const RowMat Gi = Eigen::Map<const RowMat>(G.data() + 6 * nf * i, 6, nf);
      const RowMat Ji = Eigen::Map<const RowMat>(J.data() + nf * m * i, nf, m);
      const Certificate c = fc.certify(
        Gi, Ji, Eigen::Map<const Wrench>(w_ext.data() + 6 * i), tau_min, tau_max, tau, fi);
      std::copy(c.r, c.r + 5, ci);
      ci[5] = c.finite ? 1.0 : 0.0;
      passes.mutable_data()[i] = fc.passes(c);
      double * ui = usage.mutable_data() + p * i;
      for (py::ssize_t j = 0; j < p; ++j) {
        const double fx = fi(4 * j), fy = fi(4 * j + 1), fz = fi(4 * j + 2), mz = fi(4 * j + 3);
        const double demand =
          std::hypot(fx, fy) / fc.mu1_usage() + std::abs(mz) / fc.mu2_usage();
        ui[j] = fz > 0.0 ? demand / fz : inf;
      }
      ratio.mutable_data()[i] = (tau.cwiseAbs().array() / fc.limits().array()).maxCoeff();
    }
  }
  py::dict d;
  d["kkt"] = kkt;
  d["certificate"] = cert;
  d["passes"] = passes;
  d["f"] = f;
  d["usage"] = usage;
  d["ratio"] = ratio;
  return d;
}

// The kinematics of N configurations Q (N, nq) of a tree (tree_kinematics.hpp: the
// joint tables as Tree takes them). Frame i is placed at (Rf[i], tf[i]) in joint
// fparent[i]. Returns (oMf (N, p, 4, 4), J6 (N, p, 6, nv)): LOCAL_WORLD_ALIGNED at each
// frame's origin, as Pinocchio's getFrameJacobian.
py::tuple kinematics_batch(
  Array Q, py::array_t<int64_t> parents, py::array_t<int64_t> kinds, Array axes, Array Rp,
  Array tp, py::array_t<int64_t> idx_q, py::array_t<int64_t> idx_v,
  py::array_t<int64_t> fparent, Array Rf, Array tf, int64_t nv)
{
  expect(Q.ndim() == 2, "Q of the wrong shape");
  const py::ssize_t N = Q.shape(0), nq = Q.shape(1), nj = parents.size();
  const py::ssize_t p = fparent.size();
  expect(Rf.size() == 9 * p && tf.size() == 3 * p, "joint or frame tables of the wrong shape");
  Tree tree = tree_of(parents, kinds, axes, Rp, tp, idx_q, idx_v, nq, nv);
  const int64_t * fp = fparent.data();
  for (py::ssize_t i = 0; i < p; ++i) {
    expect(fp[i] >= 0 && fp[i] < nj, "frame table out of range");
  }
  auto oMf = zeros({N, p, 4, 4}), J6 = zeros({N, p, 6, nv});
  {
    py::gil_scoped_release release;
    for (py::ssize_t n = 0; n < N; ++n) {
      tree.place(Q.data() + nq * n);
      for (py::ssize_t i = 0; i < p; ++i) {
        tree.frame(
          fp[i], Rf.data() + 9 * i, tf.data() + 3 * i, oMf.mutable_data() + 16 * (p * n + i),
          J6.mutable_data() + 6 * nv * (p * n + i));
      }
    }
  }
  return py::make_tuple(oMf, J6);
}

// The capacity LPs' answers (methods/capacity.CapacityLP, solved by DAQP as
// methods/lp.solve_lp solves them): LP k is candidate cand[k]'s (its G (6, nf) and J
// (nf, m)) for the load loads[k], over x = [f; alpha] with the rows A[k] (rows, nf + 1),
// the bounds blower, bupper (nf + 1 + rows, DAQP's form) and the cost c. Where ok[k]
// (DAQP's flag 1 or 2, x finite): the KKT violation of (x[k], lam[k]) with a zero
// Hessian, then alpha = x[k][-1] / scale[k] and the certificate of (J^T f, f) at the load
// alpha loads[k] (the planned cone). passes[k]: KKT within kkt_tolerance, alpha below
// (1 - 1e-9) alpha_max (else unbounded) and the certificate within the tolerance.
py::dict lp_finish_batch(
  const FastCycle & fc, Array G, Array J, py::array_t<int64_t> cand, Array loads,
  Array scale, Array A, Array blower, Array bupper, Array c, Array x, Array lam,
  py::array_t<bool, py::array::c_style | py::array::forcecast> ok, double kkt_tolerance,
  double alpha_max)
{
  const int m = fc.m();
  expect(G.ndim() == 3 && G.shape(1) == 6, "G of the wrong shape");
  const py::ssize_t N = G.shape(0), nf = G.shape(2), n = nf + 1;
  expect(J.size() == N * nf * m, "J of the wrong shape");
  const py::ssize_t K = cand.size();
  expect(A.ndim() == 3 && A.shape(0) == K && A.shape(2) == n, "A of the wrong shape");
  const int rows = static_cast<int>(A.shape(1));
  const py::ssize_t nb = n + rows;
  expect(
    loads.size() == 6 * K && scale.size() == K && x.size() == K * n && lam.size() == K * nb &&
    ok.size() == K && blower.size() == nb && bupper.size() == nb && c.size() == n,
    "LP arrays of the wrong shape");
  for (py::ssize_t k = 0; k < K; ++k) {
    expect(cand.data()[k] >= 0 && cand.data()[k] < N, "candidate index out of range");
  }
  auto kkt = zeros({K}), alpha = zeros({K});
  py::array_t<bool> passes(K);
  const Vec tau_max = fc.limits(), tau_min = -fc.limits(), hdiag = Vec::Zero(n);
  {
    py::gil_scoped_release release;
    for (py::ssize_t k = 0; k < K; ++k) {
      const int64_t i = cand.data()[k];
      const double * xk = x.data() + n * k;
      bool good = ok.data()[k];
      kkt.mutable_data()[k] = good ? daqp_kkt(
        hdiag, c.data(), A.data() + rows * n * k, bupper.data(), blower.data(), xk,
        lam.data() + nb * k, static_cast<int>(n), rows) :
        std::numeric_limits<double>::infinity();
      good = good && kkt.data()[k] <= kkt_tolerance && xk[nf] < (1.0 - 1e-9) * alpha_max;
      const double a = xk[nf] / scale.data()[k];
      alpha.mutable_data()[k] = a;
      if (good) {
        const Vec f = Eigen::Map<const Vec>(xk, nf);
        const RowMat Gi = Eigen::Map<const RowMat>(G.data() + 6 * nf * i, 6, nf);
        const RowMat Ji = Eigen::Map<const RowMat>(J.data() + nf * m * i, nf, m);
        const Vec tau = Ji.transpose() * f;
        const Wrench w = a * Eigen::Map<const Wrench>(loads.data() + 6 * k);
        good = fc.passes(fc.certify(Gi, Ji, w, tau_min, tau_max, tau, f));
      }
      passes.mutable_data()[k] = good;
    }
  }
  py::dict d;
  d["kkt"] = kkt;
  d["alpha"] = alpha;
  d["passes"] = passes;
  return d;
}

// One capacity LP (methods/capacity.CapacityLP) solved by DAQP as methods/lp.solve_lp
// calls it (daqp.solve: daqp_quadprog, the default settings but primal_tol, iter_limit and
// eps_prox), or by the vertex method (vertex_lp.hpp) from the zero-load wrenches, then
// checked as lp_finish_batch checks it. A holds the LP's rows; its alpha column (the
// first 6 rows' last entry) is the load direction. Returns passes; alpha. N: the vertex
// method's unknowns (VertexLPT).
template<int N>
struct CapacitySolver
{
  using LP = VertexLPT<N>;
  using VecN = typename LP::VecN;

  const FastCycle & fc;
  DaqpQuadprog quadprog;
  DaqpSettings settings;
  int nf, m, rows;
  std::vector<double> H, x, lam, bu, bl, bu0, bl0, c;
  std::vector<int> sense, sense0, sense_copy;
  double kkt_tolerance, alpha_max;
  // The vertex method's LPs: the capacity LP's rows in "<=" form (row k is sign[k] times
  // row origin[k] of [I; A], DAQP's indexing), and the zero-load phase 1 (below).
  LP lp, phase1;
  std::vector<int> origin, eq_origin;
  std::vector<double> sign;
  Vec f0;
  typename LP::State from;
  // The same LPs with the equalities E_f f + E_alpha alpha = e eliminated (zero_load):
  // f = fe + Z y + g alpha, Z an orthonormal basis of E_f's null space, fe = pinv e and
  // g = -pinv E_alpha (pinv = E_f's pseudo-inverse), so that each LP is over z = (y,
  // alpha) with inequalities only: Rf f + Ra alpha <= r becomes (Rf Z) y + (Ra - P
  // E_alpha) alpha <= r - Rf fe (P = Rf pinv). Each LP's load changes only the alpha
  // column; nz + 1 unknowns where the full LP has nf + 1 and six more rows.
  Eigen::MatrixXd Rf, Z, pinv, P;
  Vec Ra, fe;

  bool solve(
    RowMat & A, const RowMat & G, const RowMat & J, const Wrench & load, double scale,
    bool zero, double & alpha, int & iterations)
  {
    const int n = nf + 1;
    std::vector<double> & up = zero ? bu0 : bu, & lo = zero ? bl0 : bl;
    sense_copy = zero ? sense0 : sense;  // daqp.solve passes its own array each call
    DaqpProblem qp{n, n + rows, n, H.data(), c.data(), A.data(), up.data(), lo.data(),
      sense_copy.data(), nullptr, 0, 0};
    DaqpResult res{x.data(), lam.data(), 0.0, 0.0, 0, 0, 0, 0.0, 0.0};
    DaqpSettings st = settings;
    quadprog(&res, &qp, &st);
    iterations = res.iter;
    alpha = std::numeric_limits<double>::quiet_NaN();
    if (res.exitflag != 1 && res.exitflag != 2) {
      return false;
    }
    return check(A, G, J, load, scale, up, lo, alpha);
  }

  // The answer in x and lam: finite, KKT-checked, alpha below alpha_max, certified at
  // alpha times the load.
  bool check(
    const RowMat & A, const RowMat & G, const RowMat & J, const Wrench & load, double scale,
    const std::vector<double> & up, const std::vector<double> & lo, double & alpha)
  {
    const int n = nf + 1;
    for (int i = 0; i < n; ++i) {
      if (!std::isfinite(x[i])) {
        return false;
      }
    }
    const Vec hdiag = Vec::Zero(n);
    const double kkt = daqp_kkt(
      hdiag, c.data(), A.data(), up.data(), lo.data(), x.data(), lam.data(), n, rows);
    alpha = x[nf] / scale;
    if (!(kkt <= kkt_tolerance) || !(x[nf] < (1.0 - 1e-9) * alpha_max)) {
      return false;
    }
    return holds(G, J, alpha * load, Eigen::Map<const Vec>(x.data(), nf));
  }

  // Whether wrenches f hold load on the exact cones within the torque limits (certified).
  bool holds(const RowMat & G, const RowMat & J, const Wrench & load, const Vec & f) const
  {
    const Vec tau = J.transpose() * f;
    return fc.passes(fc.certify(G, J, load, -fc.limits(), fc.limits(), tau, f));
  }

  // The rows' structure in "<=" form from DAQP's bounds (the same for every candidate):
  // a finite upper bound gives +row, a finite lower one -row, equal bounds an equality.
  void layout()
  {
    const int n = nf + 1;
    for (int i = 0; i < n + rows; ++i) {
      if (bl[i] == bu[i]) {
        eq_origin.push_back(i);
        continue;
      }
      for (const double s : {1.0, -1.0}) {
        const double bound = s > 0.0 ? bu[i] : -bl[i];
        if (bound < DAQP_INF) {
          origin.push_back(i);
          sign.push_back(s);
        }
      }
    }
  }

  // Copy row i of [I; A] (DAQP's indexing), times s, into out.
  void row(const RowMat & A, int i, double s, Eigen::Ref<Vec> out) const
  {
    const int n = nf + 1;
    if (i < n) {
      out.setZero();
      out(i) = s;
    } else {
      out = s * A.row(i - n).transpose();
    }
  }

  // The vertex method's rows of this candidate (A: its G and J; the alpha column is set
  // per LP), with its equalities eliminated (above), then phase 1: zero load's wrenches
  // f0 from the LP min t over (y, t) subject to every inequality of f relaxed by t and
  // t >= 0, from y = 0 (t = the largest violation there). True where t reaches 0 (to
  // 1e-12): f0 then holds zero load on the linearized problem (the caller certifies it
  // on the exact one). False also where the equalities are dependent (DAQP then).
  bool zero_load(const RowMat & A, int & iterations)
  {
    const int n = nf + 1, ne = static_cast<int>(eq_origin.size());
    const int nr = static_cast<int>(origin.size()), nz = nf - ne;
    iterations = 0;
    if (nz < 1 || (N != Eigen::Dynamic && nz + 1 != N)) {
      return false;  // (the second: not the size this was compiled for)
    }
    Rf.resize(nr, nf);
    Ra.resize(nr);
    Vec r(nr), a(n), e(ne);
    for (int k = 0; k < nr; ++k) {
      const int i = origin[k];
      row(A, i, sign[k], a);
      Rf.row(k) = a.head(nf).transpose();
      Ra(k) = a(nf);
      r(k) = sign[k] > 0.0 ? bu[i] : -bl[i];
    }
    Eigen::MatrixXd EfT(nf, ne);
    for (int k = 0; k < ne; ++k) {
      row(A, eq_origin[k], 1.0, a);
      EfT.col(k) = a.head(nf);
      e(k) = bu[eq_origin[k]];
    }
    const Eigen::HouseholderQR<Eigen::MatrixXd> qr(EfT);
    const auto R1 = qr.matrixQR().topRows(ne).triangularView<Eigen::Upper>();
    const Vec diag = qr.matrixQR().diagonal().cwiseAbs();
    if (!(diag.minCoeff() > 1e-10 * std::max(1.0, diag.maxCoeff()))) {
      return false;  // dependent equalities (a grasp matrix of rank < 6)
    }
    const Eigen::MatrixXd Q = qr.householderQ();
    Z = Q.rightCols(nz);
    pinv = R1.solve(Q.leftCols(ne).transpose()).transpose();  // E_f pinv = I
    fe.noalias() = pinv * e;
    P.noalias() = Rf * pinv;
    lp.R.resize(nr, nz + 1);
    lp.R.leftCols(nz).noalias() = Rf * Z;
    lp.R.col(nz) = Ra;  // zero load: E_alpha = 0
    lp.r = r - Rf * fe;
    phase1.R.resize(nr + 1, nz + 1);
    phase1.r.resize(nr + 1);
    int k1 = 0;
    double t0 = 0.0;
    for (int k = 0; k < nr; ++k) {
      if (origin[k] == nf) {
        continue;  // alpha's bounds (alpha is 0 at zero load)
      }
      phase1.R.row(k1).head(nz) = lp.R.row(k).head(nz);
      phase1.R(k1, nz) = -1.0;
      phase1.r(k1) = lp.r(k);
      t0 = std::max(t0, -lp.r(k));
      ++k1;
    }
    phase1.R.row(k1) = -Vec::Unit(nz + 1, nz).transpose();
    phase1.r(k1) = 0.0;
    phase1.R.conservativeResize(k1 + 1, nz + 1);
    phase1.r.conservativeResize(k1 + 1);
    VecN start = VecN::Zero(nz + 1), cost = VecN::Unit(nz + 1, nz);
    start(nz) = t0;
    phase1.start(start, 1e-12);
    const auto status = phase1.iterate(cost, 20 * n + 200);
    iterations = phase1.iterations;
    if (status != LP::OPTIMAL || !(std::abs(phase1.s.x(nz)) <= 1e-12)) {
      return false;
    }
    start(nz) = 0.0;
    start.head(nz) = phase1.s.x.head(nz);
    f0 = fe + Z * start.head(nz);
    return base(start);
  }

  // The state the capacity LPs start from: (y0, alpha = 0), its working set alpha >= 0
  // and the rows f0 meets. False if it cannot be made.
  bool base(const VecN & start)
  {
    const int nz = static_cast<int>(start.size()) - 1;
    lp.start(start, 1e-12);
    for (int q = 0; q <= nz; ++q) {
      if (lp.s.kind[q] == LP::INEQUALITY && origin[lp.s.index[q]] == nf) {
        from = lp.s;
        return true;
      }
    }
    return false;  // alpha >= 0 not in it: the load's column would make B singular
  }

  // The capacity LP whose alpha column A holds, by the vertex method from base(); its
  // answer in x and lam (DAQP's form: the equalities' multipliers from stationarity in
  // f, Rf' lam + E_f' nu = 0), then checked.
  bool vertex(
    const RowMat & A, const RowMat & G, const RowMat & J, const Wrench & load, double scale,
    double & alpha, int & iterations)
  {
    const int n = nf + 1, ne = static_cast<int>(eq_origin.size());
    const int nr = static_cast<int>(origin.size()), nz = nf - ne;
    alpha = std::numeric_limits<double>::quiet_NaN();
    Vec ea(ne);
    for (int k = 0; k < ne; ++k) {
      const int i = eq_origin[k];
      ea(k) = i < n ? 0.0 : A(i - n, nf);  // the load's direction
    }
    lp.reset_column(nz, Ra);  // the base's column, then this LP's
    lp.s = from;
    lp.set_column(nz, Ra - P * ea);
    VecN cost = VecN::Zero(nz + 1);
    cost(nz) = -1.0;
    const auto status = lp.iterate(cost, 20 * n + 200);
    iterations = lp.iterations;
    if (status != LP::OPTIMAL) {
      return false;
    }
    const VecN & z = lp.s.x;
    const Vec f = fe + Z * z.head(nz) - pinv * (ea * z(nz));
    Vec mu = Vec::Zero(nr);
    std::fill(lam.begin(), lam.end(), 0.0);
    for (int j = 0; j <= nz; ++j) {
      const int k = lp.s.index[j];
      if (lp.s.kind[j] == LP::INEQUALITY) {
        mu(k) = std::max(0.0, lp.mu(j));  // -1e-12 read as 0
        lam[origin[k]] = sign[k] * mu(k);
      }
    }
    const Vec nu = -(pinv.transpose() * (Rf.transpose() * mu));
    for (int k = 0; k < ne; ++k) {
      lam[eq_origin[k]] = nu(k);
    }
    for (int j = 0; j < nf; ++j) {
      x[j] = f(j);
    }
    x[nf] = z(nz);
    return check(A, G, J, load, scale, bu, bl, alpha);
  }
};

// The capacity LPs of N candidates (methods/batch_capacity.CapacityBatch): for each, its
// zero-load LP (alpha fixed at 0), its load's LP (W[i] on the unit direction W[i] / max
// |W[i]|) and one per row of axes (L, 6), over x = [f; alpha] with the rows [G; J^T; S]
// (S, the friction rows of the planned polygons and f_min, shape (rows_S, nf)), the bounds
// bl, bu and sense (DAQP's form, nf + 1 + rows) and bl0, bu0, sense0 for the zero-load LP.
// With vertex, each candidate's zero-load wrenches come from the vertex method's phase 1
// (certified at zero load) and its LPs by the vertex method from them, DAQP solving any
// LP that does not pass; where phase 1 does not give certified wrenches, and without
// vertex, DAQP solves them all, the axes first.
// Returns a dict: passes (N, 2 + L: KKT-checked, below alpha_max, certified; the zero-load
// LP first, then the load's, then the axes'), alpha (N, 2 + L; NaN where none was found),
// iterations (N, 2 + L: pivots or DAQP's iterations; 0 for a load's LP answered by its
// axis's, below), vertex (N, 2 + L: answered by the vertex method). Without phase 1, the
// zero-load LP is solved only where the axes' answers do not already certify wrenches
// that hold zero load (its entry then says passes, 0 iterations).
template<int Size>
py::dict capacity_batch_n(
  const FastCycle & fc, int64_t quadprog, int64_t defaults, Array G, Array J, Array W,
  Array axes, Array S, Array bl, Array bu, py::array_t<int32_t> sense, Array bl0, Array bu0,
  py::array_t<int32_t> sense0, double primal_tol, int iter_limit, double eps_prox,
  double kkt_tolerance, double alpha_max, bool vertex)
{
  const int m = fc.m();
  expect(quadprog != 0 && defaults != 0, "no DAQP");
  expect(G.ndim() == 3 && G.shape(1) == 6, "G of the wrong shape");
  const py::ssize_t N = G.shape(0), nf = G.shape(2), n = nf + 1;
  expect(J.size() == N * nf * m && W.size() == N * 6, "J or W of the wrong shape");
  expect(axes.ndim() == 2 && axes.shape(1) == 6, "axes of the wrong shape");
  expect(S.ndim() == 2 && S.shape(1) == nf, "S of the wrong shape");
  const py::ssize_t L = axes.shape(0), rows = 6 + m + S.shape(0), nb = n + rows;
  for (const Array * a : {&bl, &bu, &bl0, &bu0}) {
    expect(a->size() == nb, "bounds of the wrong shape");
  }
  expect(sense.size() == nb && sense0.size() == nb, "sense of the wrong shape");
  CapacitySolver<Size> solver{fc, reinterpret_cast<DaqpQuadprog>(quadprog), DaqpSettings{},
    static_cast<int>(nf), m, static_cast<int>(rows),
    std::vector<double>(n * n, 0.0), std::vector<double>(n), std::vector<double>(nb),
    std::vector<double>(bu.data(), bu.data() + nb), std::vector<double>(bl.data(), bl.data() + nb),
    std::vector<double>(bu0.data(), bu0.data() + nb),
    std::vector<double>(bl0.data(), bl0.data() + nb), std::vector<double>(n, 0.0),
    std::vector<int>(sense.data(), sense.data() + nb),
    std::vector<int>(sense0.data(), sense0.data() + nb), {}, kkt_tolerance, alpha_max,
    {}, {}, {}, {}, {}, Vec(), {}, {}, {}, {}, {}, Vec(), Vec()};
  solver.layout();
  reinterpret_cast<DaqpDefaults>(defaults)(&solver.settings);
  solver.settings.primal_tol = primal_tol;
  solver.settings.iter_limit = iter_limit;
  solver.settings.eps_prox = eps_prox;
  solver.c[nf] = -1.0;
  const py::ssize_t K = 2 + L;
  py::array_t<bool> passes({N, K});
  auto alpha = zeros({N, K});
  py::array_t<int32_t> iterations({N, K});
  py::array_t<bool> by_vertex({N, K});
  std::fill(by_vertex.mutable_data(), by_vertex.mutable_data() + N * K, false);
  {
    py::gil_scoped_release release;
    RowMat A = RowMat::Zero(rows, n);
    A.bottomLeftCorner(S.shape(0), nf) = Eigen::Map<const RowMat>(S.data(), S.shape(0), nf);
    // The axes' answers by the vertex method (x, lam) for the load's LP: where the load's
    // direction W / max |W| is exactly one of the axes (a weight at the object's origin,
    // as every planned line has: (0, 0, -1, 0, 0, 0)), its LP is that axis's LP, the
    // same rows and bounds, so the axis's answer is its answer; it is checked for the
    // load (the KKT check, alpha = x_alpha / max |W|, the certificate at alpha W) and
    // not solved again. Its iterations entry says 0. An axis answered by the vertex
    // method for candidate i is by_vertex[i, 2 + j].
    std::vector<std::vector<double>> axis_x(L), axis_lam(L);
    auto same_axis = [&](py::ssize_t i, const Wrench & direction) {
        for (py::ssize_t j = 0; j < L; ++j) {
          if (by_vertex.data()[K * i + 2 + j] &&
            direction == Eigen::Map<const Wrench>(axes.data() + 6 * j))
          {
            return static_cast<int>(j);
          }
        }
        return -1;
      };
    for (py::ssize_t i = 0; i < N; ++i) {
      const RowMat Gi = Eigen::Map<const RowMat>(G.data() + 6 * nf * i, 6, nf);
      const RowMat Ji = Eigen::Map<const RowMat>(J.data() + nf * m * i, nf, m);
      A.topLeftCorner(6, nf) = Gi;
      A.block(6, 0, m, nf) = Ji.transpose();
      const Wrench w = Eigen::Map<const Wrench>(W.data() + 6 * i);
      const double scale = w.cwiseAbs().maxCoeff();
      bool from_zero = false;
      auto lp = [&](py::ssize_t k) {
          Wrench load = Wrench::Zero();
          double s = 1.0;
          if (k == 1) {
            load = w;
            s = scale;
          } else if (k > 1) {
            load = Eigen::Map<const Wrench>(axes.data() + 6 * (k - 2));
          }
          bool good = false;
          double a = std::numeric_limits<double>::quiet_NaN();
          int it = 0;
          if (k != 1 || (std::isfinite(scale) && scale > 0.0)) {
            A.topRightCorner(6, 1) = load / s;  // the zero-load LP: alpha fixed at 0
            const int same = k == 1 && from_zero ? same_axis(i, load / s) : -1;
            if (same >= 0) {  // that axis's LP: its answer, checked for this load
              std::copy(axis_x[same].begin(), axis_x[same].end(), solver.x.begin());
              std::copy(axis_lam[same].begin(), axis_lam[same].end(), solver.lam.begin());
              good = solver.check(A, Gi, Ji, load, s, solver.bu, solver.bl, a);
              by_vertex.mutable_data()[K * i + k] = good;
            } else if (k > 0 && from_zero) {
              good = solver.vertex(A, Gi, Ji, load, s, a, it);
              by_vertex.mutable_data()[K * i + k] = good;
              if (good && k > 1) {
                axis_x[k - 2].assign(solver.x.begin(), solver.x.end());
                axis_lam[k - 2].assign(solver.lam.begin(), solver.lam.end());
              }
            }
            if (!good) {
              good = solver.solve(A, Gi, Ji, load, s, k == 0, a, it);
            }
          }
          passes.mutable_data()[K * i + k] = good;
          alpha.mutable_data()[K * i + k] = a;
          iterations.mutable_data()[K * i + k] = it;
          return good;
        };
      // Phase 1's wrenches, certified at zero load: every LP from them.
      int it0 = 0;
      if (vertex && solver.zero_load(A, it0)) {
        from_zero = solver.holds(Gi, Ji, Wrench::Zero(), solver.f0);
      }
      if (from_zero) {
        passes.mutable_data()[K * i] = true;
        alpha.mutable_data()[K * i] = 0.0;
        iterations.mutable_data()[K * i] = it0;
        by_vertex.mutable_data()[K * i] = true;
        for (py::ssize_t k = 2; k < K; ++k) {  // the axes, then the load
          lp(k);
        }
        lp(1);
        continue;
      }
      // Else DAQP, the axes first: zero load is held, certified, where an axis LP's answer holds
      // alpha = 0, or by the combination of two opposite axes' answers that holds zero
      // (a_- f_+ + a_+ f_-) / (a_+ + a_-); else the zero-load LP says.
      bool zero = false, last = false;
      double a_last = 0.0;
      Vec f_last;
      for (py::ssize_t k = 2; k < K; ++k) {
        const bool good = lp(k);
        const double a = alpha.data()[K * i + k];
        const Vec f = Eigen::Map<const Vec>(solver.x.data(), nf);
        if (good && !zero) {
          const bool opposite = k % 2 == 1 && last && a_last > 0.0 && a > 0.0 &&
            (Eigen::Map<const Wrench>(axes.data() + 6 * (k - 2)) +
            Eigen::Map<const Wrench>(axes.data() + 6 * (k - 3))).isZero(0.0);
          if (a == 0.0) {
            zero = true;  // certified at 0 times its axis
          } else if (opposite) {
            zero = solver.holds(Gi, Ji, Wrench::Zero(), (a * f_last + a_last * f) / (a + a_last));
          }
        }
        if (k % 2 == 0) {
          last = good;
          a_last = a;
          f_last = f;
        }
      }
      lp(1);
      if (zero) {
        passes.mutable_data()[K * i] = true;
        alpha.mutable_data()[K * i] = 0.0;
        iterations.mutable_data()[K * i] = 0;
      } else {
        lp(0);
      }
    }
  }
  py::dict d;
  d["passes"] = passes;
  d["alpha"] = alpha;
  d["iterations"] = iterations;
  d["vertex"] = by_vertex;
  return d;
}

// capacity_batch_n with the vertex method's size fixed where it is a common one: 3, 4 or 5
// contacts give 7, 11 or 15 unknowns once the six equalities are eliminated (nf + 1 - the
// bounds that are equal).
py::dict capacity_batch(
  const FastCycle & fc, int64_t quadprog, int64_t defaults, Array G, Array J, Array W,
  Array axes, Array S, Array bl, Array bu, py::array_t<int32_t> sense, Array bl0, Array bu0,
  py::array_t<int32_t> sense0, double primal_tol, int iter_limit, double eps_prox,
  double kkt_tolerance, double alpha_max, bool vertex)
{
  int equal = 0;
  for (py::ssize_t i = 0; i < std::min(bl.size(), bu.size()); ++i) {
    equal += bl.data()[i] == bu.data()[i];
  }
  const int size = G.ndim() == 3 ? static_cast<int>(G.shape(2)) + 1 - equal : 0;
  auto run = [&](auto tag) {
      return capacity_batch_n<decltype(tag)::value>(
        fc, quadprog, defaults, G, J, W, axes, S, bl, bu, sense, bl0, bu0, sense0, primal_tol,
        iter_limit, eps_prox, kkt_tolerance, alpha_max, vertex);
    };
  switch (size) {
      case 7: return run(std::integral_constant<int, 7>());
      case 11: return run(std::integral_constant<int, 11>());
      case 15: return run(std::integral_constant<int, 15>());
      default: return run(std::integral_constant<int, Eigen::Dynamic>());
  }
}

}  // namespace

#endif  // FAST_BATCH_HPP_
