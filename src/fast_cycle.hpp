// Copyright 2026 grasp_torque_opt developers
//
// Use of this source code is governed by a BSD-style
// license that can be found in the LICENSE file or at
// https://developers.google.com/open-source/licenses/bsd
//
// SPDX-License-Identifier: BSD-3-Clause

// The node's default cycle compiled: grasp maps, tau-QP build, warm ProxSuite solve,
// KKT check and certificate in one call (grasp_torque_opt.control._fast_cycle and
// _fast_cycle_avx2, from fast_cycle.cpp and fast_cycle_avx2.cpp).
//
// It is the Python cycle (core/grasp_maps.py, core/tau_qp.py, backends/proxsuite.py,
// core/certificate.py, methods/dispatch.py) written again, rule for rule, for the case
// the node runs on every joint state: the tau-QP, the sum of squares, A = [G; J^T] of
// full column rank (a QR, no internal-force variables). Anything else, and any answer
// it cannot certify, it hands back to the Python cycle, which stays the reference
// (docs/design.md section 2.6). Pinocchio's kinematics stay in Python: this file
// takes the link placements and Jacobians that Pinocchio computed.

#ifndef FAST_CYCLE_HPP_
#define FAST_CYCLE_HPP_

#include <Eigen/Core>
#include <Eigen/QR>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <proxsuite/proxqp/dense/dense.hpp>

#include "object_loop.hpp"
#include "tree_kinematics.hpp"

namespace py = pybind11;
namespace dense = proxsuite::proxqp::dense;

using Mat = Eigen::MatrixXd;
using Vec = Eigen::VectorXd;
using RowMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using Clock = std::chrono::steady_clock;
using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

namespace
{

// Outcome codes (mirrored in grasp_torque_opt/control/compiled.py).
constexpr int CERTIFIED = 0;     // certified optimum
constexpr int NOT_HANDLED = 1;   // inputs this path does not take (rank, normals): Python
constexpr int BAD_DATA = 2;      // QP data not finite or bounds inverted
constexpr int NOT_SOLVED = 3;    // ProxSuite did not call it solved
constexpr int NOT_CERTIFIED = 4;  // solved, but the certificate failed
constexpr int TIMED_OUT = 5;     // the time budget stopped the solver

double seconds_since(Clock::time_point t0)
{
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

Eigen::Matrix3d skew(const Eigen::Vector3d & v)
{
  Eigen::Matrix3d s;
  s << 0.0, -v(2), v(1), v(2), 0.0, -v(0), -v(1), v(0), 0.0;
  return s;
}

// contact_frame.contact_rotations for one contact; false where Python raises.
bool contact_rotation(
  const Eigen::Vector3d & normal, const double * tangent,
  Eigen::Matrix3d & R)
{
  const double nx = normal(0), ny = normal(1), nz = normal(2);
  const double norm = std::sqrt(nx * nx + ny * ny + nz * nz);
  if (!std::isfinite(norm) || norm < 1e-9) {
    return false;
  }
  const double zx = nx / norm, zy = ny / norm, zz = nz / norm;
  double xx, xy, xz;
  if (tangent == nullptr) {
    const double ax = std::abs(zx), ay = std::abs(zy), az = std::abs(zz);
    if (ax <= ay && ax <= az) {
      xx = 0.0, xy = -zz, xz = zy;
    } else if (ay <= az) {
      xx = zz, xy = 0.0, xz = -zx;
    } else {
      xx = -zy, xy = zx, xz = 0.0;
    }
  } else {
    double tx = tangent[0], ty = tangent[1], tz = tangent[2];
    const double tn = std::sqrt(tx * tx + ty * ty + tz * tz);
    if (!std::isfinite(tn) || tn < 1e-9) {
      return false;
    }
    tx /= tn, ty /= tn, tz /= tn;
    const double d = tx * zx + ty * zy + tz * zz;
    xx = tx - d * zx, xy = ty - d * zy, xz = tz - d * zz;
    if (std::sqrt(xx * xx + xy * xy + xz * xz) < 1e-6) {
      return false;
    }
  }
  const double k = 1.0 / std::sqrt(xx * xx + xy * xy + xz * xz);
  xx *= k, xy *= k, xz *= k;
  const double yx = zy * xz - zz * xy, yy = zz * xx - zx * xz, yz = zx * xy - zy * xx;
  R << xx, yx, zx, xy, yy, zy, xz, yz, zz;
  return true;
}

template<typename Derived>
double max_abs(const Eigen::MatrixBase<Derived> & a)
{
  return a.size() ? a.cwiseAbs().maxCoeff() : 0.0;
}

struct Settings
{
  double eps_abs, eps_rel, eps_primal_inf;
  int max_iter, max_iter_in;
  double kkt_tolerance, certificate_tolerance, qr_rtol, box_margin;
  double inner_iteration_s, estimate_decay, primary_share;
};

using Wrench = Eigen::Matrix<double, 6, 1>;

// DAQP's "infinite" bound (backends/daqp.DAQP_INF).
constexpr double DAQP_INF = 1e30;

// DAQP's C interface (version 0.11.0: include/types.h and include/api.h), as the daqp
// Python module's extension exports it: the three structs daqp_quadprog reads and writes.
// grasp_torque_opt.backends.daqp.daqp_entry gives the functions' addresses only
// where the installed daqp is that version, so that these layouts are its own.
struct DaqpProblem
{
  int n, m, ms;
  double * H, * f, * A, * bupper, * blower;
  int * sense, * break_points;
  int nh, problem_type;
};
struct DaqpSettings
{
  double primal_tol, dual_tol, zero_tol, pivot_tol, progress_tol;
  int cycle_tol, iter_limit;
  double fval_bound, eps_prox, eta_prox, rho_soft, rel_subopt, abs_subopt, sing_tol;
  double refactor_tol, time_limit, w_soft;
  int eq_reduction, presolve;
};
struct DaqpResult
{
  double * x, * lam;
  double fval, soft_slack;
  int exitflag, iter, nodes;
  double solve_time, setup_time;
};
using DaqpQuadprog = void (*)(DaqpResult *, DaqpProblem *, DaqpSettings *);
using DaqpDefaults = void (*)(DaqpSettings *);

// backends/daqp.kkt_violation of min 1/2 x'Hx + g'x, H = diag(hdiag), blower <= [x; A x]
// <= bupper, with DAQP's multipliers lam (bounds on x first).
double daqp_kkt(
  const Vec & hdiag, const double * g, const double * A, const double * up,
  const double * lo, const double * x, const double * lam, int n, int rows)
{
  Eigen::Map<const RowMat> Am(A, rows, n);
  Eigen::Map<const Vec> xv(x, n), lv(lam, n + rows);
  Vec grad = hdiag.cwiseProduct(xv);
  if (g != nullptr) {
    grad += Eigen::Map<const Vec>(g, n);
  }
  Vec residual = Am.transpose() * lv.tail(rows) + lv.head(n) + grad;
  const Vec Ax = Am * xv;
  double infeasible = -std::numeric_limits<double>::infinity();
  double complementarity = -std::numeric_limits<double>::infinity();
  for (int i = 0; i < n + rows; ++i) {
    const double v = i < n ? xv(i) : Ax(i - n);
    const double to_upper = up[i] - v, to_lower = v - lo[i];
    infeasible = std::max(infeasible, -std::min(to_upper, to_lower));
    complementarity = std::max(
      complementarity, std::max(lam[i] * to_upper, -lam[i] * to_lower));
  }
  return std::max(
    {max_abs(residual) / std::max(1.0, max_abs(grad)), infeasible, complementarity});
}

// The maps stage's inputs: one cycle's kinematics as Pinocchio gave them (borrowed).
struct Kinematics
{
  int p = 0, nv = 0;
  const double * oMf = nullptr;      // (p, 4, 4) link placements, row-major
  const double * J6 = nullptr;       // (p, 6, nv) LOCAL_WORLD_ALIGNED link Jacobians
  const double * points = nullptr;   // (p, 3) contact points in their link frames
  const double * normals = nullptr;  // (p, 3) base axes, where has_normal
  const bool * has_normal = nullptr;
  const double * tangents = nullptr;  // (p, 3) base axes, where has_tangent
  const bool * has_tangent = nullptr;
  Eigen::Vector3d c = Eigen::Vector3d::Zero();  // object origin, base frame
};

// The maps stage's output (core/grasp_maps.GraspMaps).
struct Maps
{
  RowMat G, J, positions, rotations;  // rotations: p rows of 9 (row-major R_i)
};

// The build stage's output (core/tau_qp.TauQP with k = 0: no N, x = tau), and the
// certificate's torque bounds.
struct QPData
{
  Mat H, A, C;
  Vec g, b, l, u, l_box, u_box;
  Mat pinv;  // [M1 M2] = pinv([G; J^T]), 4p x (6 + m)
  Vec w, tau_min, tau_max;
  Mat qr, Q;  // the build's work: [G; J^T]'s QR (householder_qr) and its Q
  Vec qr_tau;

  int n_eq() const {return static_cast<int>(A.rows());}
  auto M1() const {return pinv.leftCols(6);}
  auto M2() const {return pinv.rightCols(pinv.cols() - 6);}
};

// The certify stage's output (core/certificate.Certificate without its tolerance).
struct Certificate
{
  double r[5] = {0, 0, 0, 0, 0};  // equilibrium, torque, cone, normal_force, limit
  bool finite = false;
};

// One cycle's answer, read by compiled.py.
struct Answer
{
  int code = NOT_HANDLED;
  std::string message;
  Vec tau, f;
  Maps maps;
  int iterations = 0;
  bool warm = false;        // the answer came from a warm start
  int warm_solves = 0;      // warm starts tried in this call (0 or 1)
  int redone_cold = 0;      // warm answers redone cold in this call
  Certificate cert;
  Vec usage;
  double max_torque_ratio = 0.0;
  double solve_time_s = 0.0;
  double t_maps = 0.0, t_build = 0.0, t_solve = 0.0, t_certify = 0.0;
};

// d (n entries) times the reflector I - t v v^T, v = [1; v[1:n]] (v[0] is not read).
inline void reflect(const double * v, double t, int n, double * d)
{
  double s = d[0];
  for (int i = 1; i < n; ++i) {
    s += v[i] * d[i];
  }
  s *= t;
  d[0] -= s;
  for (int i = 1; i < n; ++i) {
    d[i] -= s * v[i];
  }
}

// Householder QR of a (rows >= cols) in place, as LAPACK's dgeqr2 (numpy's QR, via
// dgeqrf) and Eigen's HouseholderQR write it: R on and above the diagonal, each
// reflector's essential part below it, its coefficient in tau (H_k = I - tau_k v v^T,
// v = [1; essential]); a column already zero below its diagonal takes tau 0. Written
// here, not Eigen's, for the sizes of a hand (22 x 16 for the Allegro): Eigen's
// dynamic-size kernels spend more on their dispatch than on the arithmetic: with this
// and the Q below, the build stage's own timings fell from 15-19 to 10-11 us on the
// bundled params file (docs/benchmarks.md, item 4 at c033dea).
void householder_qr(Mat & a, Vec & tau)
{
  const int rows = static_cast<int>(a.rows()), cols = static_cast<int>(a.cols());
  tau.resize(cols);
  for (int k = 0; k < cols; ++k) {
    double * v = a.col(k).data() + k;
    const int n = rows - k;
    double tail = 0.0;
    for (int i = 1; i < n; ++i) {
      tail += v[i] * v[i];
    }
    const double c0 = v[0];
    if (tail <= std::numeric_limits<double>::min()) {
      tau(k) = 0.0;
      for (int i = 1; i < n; ++i) {
        v[i] = 0.0;
      }
      continue;
    }
    const double beta = c0 >= 0.0 ? -std::sqrt(c0 * c0 + tail) : std::sqrt(c0 * c0 + tail);
    const double scale = 1.0 / (c0 - beta);
    for (int i = 1; i < n; ++i) {
      v[i] *= scale;
    }
    const double t = (beta - c0) / beta;
    tau(k) = t;
    v[0] = beta;
    for (int j = k + 1; j < cols; ++j) {
      reflect(v, t, n, a.col(j).data() + k);
    }
  }
}

// Q (rows x rows) of householder_qr's reflectors, H_0 H_1 ... H_(cols-1) (LAPACK's
// dorgqr, Eigen's householderQ()): applied from the last to the identity, each only
// where it can change it.
void householder_q(const Mat & a, const Vec & tau, Mat & Q)
{
  const int rows = static_cast<int>(a.rows()), cols = static_cast<int>(a.cols());
  Q.setIdentity(rows, rows);
  for (int k = cols - 1; k >= 0; --k) {
    const double * v = a.col(k).data() + k;
    const double t = tau(k);
    const int n = rows - k;
    for (int j = k; j < rows; ++j) {
      reflect(v, t, n, Q.col(j).data() + k);
    }
  }
}

// A Tree from the joint tables as Python passes them (TreeKinematics.tables); a
// ValueError where their shapes do not agree (Tree checks their values).
Tree tree_of(
  const py::array_t<int64_t> & parents, const py::array_t<int64_t> & kinds, const Array & axes,
  const Array & Rp, const Array & tp, const py::array_t<int64_t> & idx_q,
  const py::array_t<int64_t> & idx_v, int64_t nq, int64_t nv)
{
  const py::ssize_t nj = parents.size();
  if (kinds.size() != nj || axes.size() != 3 * nj || Rp.size() != 9 * nj ||
    tp.size() != 3 * nj || idx_q.size() != nj || idx_v.size() != nj)
  {
    throw std::invalid_argument("joint or frame tables of the wrong shape");
  }
  return Tree(
    nj, parents.data(), kinds.data(), axes.data(), Rp.data(), tp.data(), idx_q.data(),
    idx_v.data(), nq, nv);
}

// The compiled cycle bound to one grasp's friction, weights, limits and settings.
//
// solve() runs one cycle: run() calls the four stages in order, each the twin of a
// Python stage and exposed on its own for the parity tests
// (test/control/test_compiled_stages.py):
//   maps      core/grasp_maps.compute_grasp_maps  contact frames, G, J
//   build     core/tau_qp.build_tau_qp            the tau-QP (the QR branch)
//   solve_qp  backends/proxsuite.TauQPSolver      the warm ProxSuite solve, KKT-checked
//   certify   core/certificate.certify            the certificate of (tau, f)
class FastCycle
{
public:
  FastCycle(
    py::array_t<int64_t> idx_v, Array S_i, Array b_i, Array weights, Array limits,
    double mu1, double mu2, double mu1_usage, double mu2_usage,
    double min_normal_force, bool warm_start, const Settings & settings)
  : mu1_(mu1), mu2_(mu2), mu1_usage_(mu1_usage), mu2_usage_(mu2_usage),
    fmin_(min_normal_force), warm_start_(warm_start), s_(settings)
  {
    auto iv = idx_v.unchecked<1>();
    for (py::ssize_t i = 0; i < iv.shape(0); ++i) {
      idx_v_.push_back(iv(i));
    }
    m_ = static_cast<int>(idx_v_.size());
    if (S_i.ndim() != 2 || S_i.shape(1) != 4 || b_i.ndim() != 1 ||
      b_i.shape(0) != S_i.shape(0))
    {
      throw std::invalid_argument("S_i must be (rows, 4) and b_i (rows,)");
    }
    S_i_ = Eigen::Map<const RowMat>(S_i.data(), S_i.shape(0), 4);
    b_i_ = Eigen::Map<const Vec>(b_i.data(), b_i.shape(0));
    if (weights.size() != m_ || limits.size() != m_) {
      throw std::invalid_argument("weights and limits need one entry per actuated joint");
    }
    weights_ = Eigen::Map<const Vec>(weights.data(), m_);
    limits_ = Eigen::Map<const Vec>(limits.data(), m_);
  }

  // Solve with DAQP (backends/daqp.DaqpSolver) instead of ProxSuite: its C entry
  // daqp_quadprog at address quadprog, daqp_default_settings at defaults (as
  // backends/daqp.daqp_entry finds them), with its primal_tol, iter_limit and
  // eq_reduction (daqp.DaqpSettings), and iteration_s the time per iteration assumed
  // before one is measured (daqp.ITERATION_S).
  void use_daqp(
    int64_t quadprog, int64_t defaults, double primal_tol, int iter_limit, int eq_reduction,
    double iteration_s)
  {
    if (quadprog == 0 || defaults == 0 || iter_limit < 1) {
      throw std::invalid_argument("use_daqp: no DAQP entry, or an iteration cap below 1");
    }
    quadprog_ = reinterpret_cast<DaqpQuadprog>(quadprog);
    reinterpret_cast<DaqpDefaults>(defaults)(&daqp_settings_);
    daqp_settings_.primal_tol = primal_tol;
    daqp_settings_.iter_limit = iter_limit;
    daqp_settings_.eq_reduction = eq_reduction;
    daqp_settings_.eps_prox = 0.0;  // H = 2 diag(w) is positive definite: no z here
    daqp_iteration_s_ = iteration_s;
    dims_ = {-1, -1, -1};
  }

  bool uses_daqp() const {return quadprog_ != nullptr;}

  // One cycle. oMf: (p, 4, 4) link placements; J6: (p, 6, nv) LOCAL_WORLD_ALIGNED
  // link Jacobians; points: (p, 3) contact points in their link frames; normals and
  // tangents (p, 3) in base axes, used where has_normal / has_tangent; c (3); w_ext (6);
  // offset (m) added to tau before commanding (g(q)) or empty; time_left [s] (< 0:
  // none).
  Answer solve(
    Array oMf, Array J6, Array points, Array normals, py::array_t<bool> has_normal,
    Array tangents, py::array_t<bool> has_tangent, Array c, Array w_ext,
    Array offset, double time_left)
  {
    Answer a;
    const auto t0 = Clock::now();
    Kinematics k;
    if (w_ext.size() != 6 || (offset.size() != 0 && offset.size() != m_) ||
      !borrow(oMf, J6, points, normals, has_normal, tangents, has_tangent, c, k, a.message))
    {
      if (a.message.empty()) {
        a.message = "inputs of the wrong shape";
      }
      return a;
    }
    run_released(a, k, w_ext, offset, time_left, t0);
    return a;
  }

  // Compute the contact links' kinematics here, from the hand's tree (Tree's tables,
  // as kinematics_batch takes them), for solve_q.
  void use_tree(
    py::array_t<int64_t> parents, py::array_t<int64_t> kinds, Array axes, Array Rp,
    Array tp, py::array_t<int64_t> idx_q, py::array_t<int64_t> idx_v, int64_t nq, int64_t nv)
  {
    for (int64_t j : idx_v_) {
      if (j < 0 || j >= nv) {
        throw std::invalid_argument("joint index out of range");
      }
    }
    tree_ = std::make_unique<Tree>(tree_of(parents, kinds, axes, Rp, tp, idx_q, idx_v, nq, nv));
  }

  bool uses_tree() const {return tree_ != nullptr;}

  // One cycle at configuration q (nq) with the kinematics of use_tree(): contact i on the
  // link frame placed at (Rf[i], tf[i]) in joint fparent[i]; the rest as solve().
  Answer solve_q(
    Array q, py::array_t<int64_t> fparent, Array Rf, Array tf, Array points, Array normals,
    py::array_t<bool> has_normal, Array tangents, py::array_t<bool> has_tangent, Array c,
    Array w_ext, Array offset, double time_left)
  {
    Answer a;
    const auto t0 = Clock::now();
    const int p = static_cast<int>(fparent.size());
    Kinematics k;
    if (tree_ == nullptr) {
      a.message = "no tree kinematics (use_tree)";
      return a;
    }
    const int64_t nv = tree_->nv();
    bool fits = q.size() == tree_->nq() && Rf.size() == 9 * p && tf.size() == 3 * p &&
      w_ext.size() == 6 && (offset.size() == 0 || offset.size() == m_) && p > 0;
    for (int i = 0; fits && i < p; ++i) {
      fits = fparent.data()[i] >= 0 && fparent.data()[i] < tree_->joints();
    }
    if (!fits || !borrow_contacts(p, points, normals, has_normal, tangents, has_tangent, c, k)) {
      a.message = "inputs of the wrong shape";
      return a;
    }
    oMf_.resize(16 * p);
    J6_.resize(6 * nv * p);
    tree_->place(q.data());
    for (int i = 0; i < p; ++i) {
      tree_->frame(
        fparent.data()[i], Rf.data() + 9 * i, tf.data() + 3 * i, oMf_.data() + 16 * i,
        J6_.data() + 6 * nv * i);
    }
    k.p = p;
    k.nv = static_cast<int>(nv);
    k.oMf = oMf_.data();
    k.J6 = J6_.data();
    run_released(a, k, w_ext, offset, time_left, t0);
    return a;
  }

  // The contact list of the cycles to come, as solve_q takes it (held, not copied:
  // the caller does not change these arrays), for solve_bound.
  void bind_contacts(
    py::array_t<int64_t> fparent, Array Rf, Array tf, Array points, Array normals,
    py::array_t<bool> has_normal, Array tangents, py::array_t<bool> has_tangent)
  {
    bound_ = std::make_unique<Bound>(
      Bound{fparent, Rf, tf, points, normals, has_normal, tangents, has_tangent});
  }

  // solve_q on the contacts of bind_contacts: the cycle's own arrays only (q, the object
  // origin, the load, the torque offset) cross from Python.
  Answer solve_bound(Array q, Array c, Array w_ext, Array offset, double time_left)
  {
    if (bound_ == nullptr) {
      Answer a;
      a.message = "no contacts bound (bind_contacts)";
      return a;
    }
    const Bound & b = *bound_;
    return solve_q(
      q, b.fparent, b.Rf, b.tf, b.points, b.normals, b.has_normal, b.tangents, b.has_tangent,
      c, w_ext, offset, time_left);
  }

  // run() on checked inputs (w_ext of 6, offset of m or none), the GIL released.
  void run_released(
    Answer & a, const Kinematics & k, const Array & w_ext, const Array & offset,
    double time_left, Clock::time_point t0)
  {
    Eigen::Map<const Wrench> w_ext_v(w_ext.data());
    Vec off = offset.size() ? Vec(Eigen::Map<const Vec>(offset.data(), m_)) :
      Vec::Zero(m_);
    // The GIL is released from here on: nothing below touches a Python object.
    py::gil_scoped_release release;
    run(a, k, w_ext_v, off, time_left, t0);
  }

  // The contact arrays of p contacts as the maps stage takes them; false where they do
  // not fit.
  bool borrow_contacts(
    int p, const Array & points, const Array & normals, const py::array_t<bool> & has_normal,
    const Array & tangents, const py::array_t<bool> & has_tangent, const Array & c,
    Kinematics & k) const
  {
    if (points.ndim() != 2 || points.shape(0) != p || points.shape(1) != 3 ||
      normals.ndim() != 2 || normals.shape(0) != p || normals.shape(1) != 3 ||
      tangents.ndim() != 2 || tangents.shape(0) != p || tangents.shape(1) != 3 ||
      has_normal.size() != p || has_tangent.size() != p || c.size() != 3 || p == 0)
    {
      return false;
    }
    k.points = points.data();
    k.normals = normals.data();
    k.has_normal = has_normal.data();
    k.tangents = tangents.data();
    k.has_tangent = has_tangent.data();
    k.c = Eigen::Map<const Eigen::Vector3d>(c.data());
    return true;
  }

  // The arrays of one cycle's kinematics as the maps stage takes them; false and why
  // where they do not fit.
  bool borrow(
    const Array & oMf, const Array & J6, const Array & points, const Array & normals,
    const py::array_t<bool> & has_normal, const Array & tangents,
    const py::array_t<bool> & has_tangent, const Array & c, Kinematics & k,
    std::string & why) const
  {
    const int p = static_cast<int>(oMf.shape(0));
    if (oMf.ndim() != 3 || oMf.shape(1) != 4 || oMf.shape(2) != 4 || J6.ndim() != 3 ||
      J6.shape(0) != p || J6.shape(1) != 6 ||
      !borrow_contacts(p, points, normals, has_normal, tangents, has_tangent, c, k))
    {
      why = "inputs of the wrong shape";
      return false;
    }
    const int nv = static_cast<int>(J6.shape(2));
    for (int64_t j : idx_v_) {
      if (j < 0 || j >= nv) {
        why = "joint index out of range";
        return false;
      }
    }
    k.p = p;
    k.nv = nv;
    k.oMf = oMf.data();
    k.J6 = J6.data();
    return true;
  }

  // -- maps (core/grasp_maps.compute_grasp_maps) ---------------------------------------
  // Contact frames, G (6 x 4p) and J (4p x m); false and why where Python raises.
  bool maps(const Kinematics & k, Maps & out, std::string & why) const
  {
    const int p = k.p, nv = k.nv, m = m_;
    out.G.setZero(6, 4 * p);
    out.J.resize(4 * p, m);
    out.positions.resize(p, 3);
    out.rotations.resize(p, 9);
    for (int i = 0; i < p; ++i) {
      Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>> M(k.oMf + 16 * i);
      const Eigen::Matrix3d Rl = M.topLeftCorner<3, 3>();
      const Eigen::Vector3d o = M.topRightCorner<3, 1>();
      const Eigen::Vector3d point =
        Rl * Eigen::Map<const Eigen::Vector3d>(k.points + 3 * i) + o;
      Eigen::Vector3d n;
      if (k.has_normal[i]) {
        n = Eigen::Map<const Eigen::Vector3d>(k.normals + 3 * i);
      } else {
        n = k.c - point;
        if (n.dot(n) < 1e-18) {
          why = "a normal cannot be defaulted";
          return false;
        }
      }
      Eigen::Matrix3d R;
      if (!contact_rotation(n, k.has_tangent[i] ? k.tangents + 3 * i : nullptr, R)) {
        why = "a contact frame cannot be made";
        return false;
      }
      for (int j = 0; j < 3; ++j) {
        out.positions(i, j) = point(j);
      }
      Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(out.rotations.row(i).data()) = R;
      out.G.block<3, 3>(0, 4 * i) = R;
      out.G.block<3, 3>(3, 4 * i) = skew(point - k.c) * R;
      out.G.block<3, 1>(3, 4 * i + 3) = R.col(2);
      Eigen::Map<const RowMat> Jl(k.J6 + 6 * nv * i, 6, nv);
      Eigen::Matrix<double, 6, Eigen::Dynamic> Ja(6, m);
      for (int j = 0; j < m; ++j) {
        Ja.col(j) = Jl.col(idx_v_[j]);
      }
      const auto Jv = Ja.topRows<3>();
      const auto Jw = Ja.bottomRows<3>();
      out.J.block(4 * i, 0, 3, m) = R.transpose() * (Jv - skew(point - o) * Jw);
      out.J.row(4 * i + 3) = R.col(2).transpose() * Jw;
    }
    return true;
  }

  // -- build (core/tau_qp.build_tau_qp, the QR branch of decompose) --------------------
  // The tau-QP of G (6 x 4p) and J (4p x m) into qp; false and why where A = [G; J^T]
  // needs the SVD branch (the Python cycle's) or is not finite.
  bool build(
    const RowMat & G, const RowMat & J, const Wrench & w_ext, const Vec & off,
    QPData & qp, std::string & why) const
  {
    const int m = m_, cols = static_cast<int>(G.cols()), p = cols / 4;
    const int rows = 6 + m;
    if (rows < cols) {
      why = "A = [G; J^T] has more columns than rows";
      return false;
    }
    Mat & packed = qp.qr;
    packed.resize(rows, cols);
    packed.topRows(6) = G;
    packed.bottomRows(m) = J.transpose();
    if (!packed.allFinite()) {
      why = "maps not finite";
      return false;
    }
    householder_qr(packed, qp.qr_tau);
    const Vec d = packed.diagonal().head(cols).cwiseAbs();
    if (!(d.minCoeff() > s_.qr_rtol * d.maxCoeff())) {
      why = "A = [G; J^T] is not of full column rank";
      return false;
    }
    Mat & Q = qp.Q;
    householder_q(packed, qp.qr_tau, Q);  // rows x rows
    const auto Rup = packed.topRows(cols).triangularView<Eigen::Upper>();
    qp.pinv = Q.leftCols(cols).transpose();
    Rup.solveInPlace(qp.pinv);  // cols x rows
    const auto U_perp = Q.rightCols(rows - cols);
    const auto M1 = qp.M1();
    const auto M2 = qp.M2();
    qp.w = -w_ext;
    const int block = static_cast<int>(S_i_.rows()), n_in = block * p;
    qp.C.resize(n_in, m);
    qp.u.resize(n_in);
    const Vec f_w = M1 * qp.w;  // M1 w
    for (int i = 0; i < p; ++i) {
      qp.C.middleRows(block * i, block) = S_i_ * M2.middleRows(4 * i, 4);
      qp.u.segment(block * i, block) = b_i_ - S_i_ * f_w.segment<4>(4 * i);
    }
    qp.H.setZero(m, m);
    qp.H.diagonal() = 2.0 * weights_;
    qp.g.setZero(m);
    qp.A = U_perp.bottomRows(m).transpose();
    qp.b.noalias() = -U_perp.topRows(6).transpose() * qp.w;
    qp.tau_min = -limits_ - off;
    qp.tau_max = limits_ - off;
    qp.l_box = qp.tau_min.array() + s_.box_margin;
    qp.u_box = qp.tau_max.array() - s_.box_margin;
    qp.l.setConstant(n_in, -std::numeric_limits<double>::infinity());
    return true;
  }

  // -- solve (backends/proxsuite.TauQPSolver.solve) -------------------------------------
  // check_data, then ProxSuite on qp: cold on a new size or when cold, else warm if
  // enabled, a warm answer that ProxSuite does not call solved or that fails the KKT
  // check redone cold. True with a.tau and a.f (TauQP.wrenches) set when ProxSuite
  // solved it; else false with a.code and a.message.
  bool solve_qp(
    const QPData & qp, bool cold, bool has_deadline, Clock::time_point deadline,
    Answer & a)
  {
    if (cold && a.warm) {  // the caller's redo of a warm answer off the certificate
      a.redone_cold += 1;
    }
    a.warm = false;
    // tau_qp.check_data: one sum per array, then the bounds.
    const double total = qp.H.sum() + qp.g.sum() + qp.A.sum() + qp.b.sum() + qp.C.sum() +
      qp.u.sum();
    if (!std::isfinite(total)) {
      a.code = BAD_DATA;
      a.message = "QP data not finite";
      return false;
    }
    if (!(qp.l_box.array() <= qp.u_box.array()).all()) {
      a.code = BAD_DATA;
      a.message = "QP bounds NaN or inverted (lower > upper)";
      return false;
    }
    if (quadprog_ != nullptr) {
      return solve_daqp(qp, cold, has_deadline, deadline, a);
    }
    const int m = m_, n_eq = qp.n_eq(), n_in = static_cast<int>(qp.C.rows());
    bool stopped = false, warm = false;
    try {
      const std::tuple<int, int, int> dims(m, n_eq, n_in);
      if (!qp_ || dims != dims_) {
        inner_s_ = s_.inner_iteration_s *
          std::max(1.0, static_cast<double>(m) * (m + n_eq + n_in) / (16.0 * 144.0));
        init(qp);
        dims_ = dims;
      } else {
        warm = warm_start_ && !cold;
        qp_->settings.initial_guess =
          warm ? proxsuite::proxqp::InitialGuessStatus::WARM_START_WITH_PREVIOUS_RESULT :
          proxsuite::proxqp::InitialGuessStatus::NO_INITIAL_GUESS;
        update(qp);
      }
      a.iterations += solve_until(has_deadline, deadline, stopped);
      if (warm) {
        a.warm_solves += 1;
        const auto & r = qp_->results;
        warm = r.info.status == proxsuite::proxqp::QPSolverOutput::PROXQP_SOLVED &&
          kkt_violation(qp, r.x, r.y, r.z) <= s_.kkt_tolerance;
        if (!warm && !stopped) {  // the same data, cold
          a.redone_cold += 1;
          qp_->settings.initial_guess = proxsuite::proxqp::InitialGuessStatus::NO_INITIAL_GUESS;
          a.iterations += solve_until(has_deadline, deadline, stopped);
        }
      }
    } catch (const std::exception & e) {
      qp_.reset();
      a.code = NOT_SOLVED;
      a.message = std::string("ProxSuite failed: ") + e.what();
      return false;
    }
    if (stopped) {
      a.code = TIMED_OUT;
      a.message = "time budget spent after " + std::to_string(a.iterations) + " iterations";
      return false;
    }
    const auto & r = qp_->results;
    a.message = solver_status(r.info.status);
    if (r.info.status != proxsuite::proxqp::QPSolverOutput::PROXQP_SOLVED) {
      a.code = NOT_SOLVED;
      return false;
    }
    a.warm = warm;
    a.tau = r.x.head(m);
    a.f = qp.M1() * qp.w + qp.M2() * a.tau;
    return true;
  }

  // -- solve with DAQP (backends/daqp.DaqpSolver.solve) --------------------------------
  // The tau-QP in DAQP's form: bounds on tau first, then the equalities, then the cone
  // rows. Cold on a new size or when cold, else warm if enabled: started from the active
  // set of the last solved QP (the signs of its multipliers; DaqpSolver's workspace keeps
  // its working set). A warm answer that is not optimal by DAQP's flag and the KKT check
  // is redone cold from the same data, the two sharing a cap fitted to the deadline.
  bool solve_daqp(
    const QPData & qp, bool cold, bool has_deadline, Clock::time_point deadline,
    Answer & a)
  {
    const int m = m_, n_eq = qp.n_eq(), n_in = static_cast<int>(qp.C.rows());
    const int rows = n_eq + n_in;
    if (has_deadline && Clock::now() >= deadline) {
      a.code = TIMED_OUT;
      a.message = "time budget spent before DAQP started";
      return false;
    }
    const std::tuple<int, int, int> dims(m, n_eq, n_in);
    if (dims != dims_) {
      ++inits_;
      dims_ = dims;
      // daqp.size_factor: a new size, a guess scaled from the Allegro's tau-QP.
      iter_s_ = daqp_iteration_s_ *
        std::max(1.0, static_cast<double>(m) * (m + rows) / (16.0 * 144.0));
      have_active_ = false;
      sense0_.assign(m + rows, 0);
      std::fill(sense0_.begin() + m, sense0_.begin() + m + n_eq, 5);  // equality
    }
    daqp_A_.resize(rows, m);
    daqp_A_.topRows(n_eq) = qp.A;
    daqp_A_.bottomRows(n_in) = qp.C;
    up_.resize(m + rows);
    lo_.resize(m + rows);
    for (int j = 0; j < m; ++j) {
      up_(j) = std::min(qp.u_box(j), DAQP_INF);
      lo_(j) = std::max(qp.l_box(j), -DAQP_INF);
    }
    up_.segment(m, n_eq) = qp.b;
    lo_.segment(m, n_eq) = qp.b;
    up_.tail(n_in) = qp.u;
    lo_.tail(n_in).setConstant(-DAQP_INF);
    H_ = qp.H;
    g_ = qp.g;
    x_.resize(m);
    lam_.resize(m + rows);
    int limit = daqp_settings_.iter_limit;
    if (has_deadline) {
      const double left = std::chrono::duration<double>(deadline - Clock::now()).count();
      limit = std::min(limit, std::max(1, static_cast<int>(left / iter_s_)));
    }
    const bool warm = warm_start_ && !cold && have_active_;
    const auto t0 = Clock::now();
    int iterations = 0;
    int flag = daqp_run(warm, limit, iterations);
    double kkt = daqp_answer_kkt(flag, rows);
    if (warm) {
      a.warm_solves += 1;
      a.warm = kkt <= s_.kkt_tolerance;
      if (!a.warm) {
        a.redone_cold += 1;
        const int rest = limit < daqp_settings_.iter_limit ?
          std::max(1, limit - iterations) : limit;
        int more = 0;
        flag = daqp_run(false, rest, more);
        iterations += more;
        kkt = daqp_answer_kkt(flag, rows);
      }
    }
    if (iterations) {
      iter_s_ = std::max(seconds_since(t0) / iterations, s_.estimate_decay * iter_s_);
    }
    a.iterations += iterations;
    a.message = "DAQP exit flag " + std::to_string(flag);
    if (flag != 1 || !(kkt <= s_.kkt_tolerance)) {
      have_active_ = false;
      a.code = NOT_SOLVED;
      if (flag == 1) {
        a.message += ", but KKT violated by " + std::to_string(kkt);
      }
      return false;
    }
    // The next warm start: the rows this answer holds at a bound, on that bound.
    active_ = sense0_;
    for (int i = 0; i < m + rows; ++i) {
      if (i >= m && i < m + n_eq) {
        continue;
      }
      active_[i] = lam_(i) > 0.0 ? 1 : lam_(i) < 0.0 ? 3 : 0;  // ACTIVE, ACTIVE + LOWER
    }
    have_active_ = true;
    a.tau = x_;
    a.f = qp.M1() * qp.w + qp.M2() * a.tau;
    return true;
  }

  // -- certify (core/certificate.certify) -----------------------------------------------
  // The residuals of (tau, f) against the exact problem: G f + w_ext = 0, J^T f = tau,
  // the exact cone, the minimum normal force and the torque bounds.
  Certificate certify(
    const RowMat & G, const RowMat & J, const Wrench & w_ext, const Vec & tau_min,
    const Vec & tau_max, const Vec & tau, const Vec & f) const
  {
    Certificate c;
    if (!std::isfinite(tau.sum() + f.sum())) {
      std::fill(c.r, c.r + 5, std::numeric_limits<double>::infinity());
      return c;
    }
    c.finite = true;
    const int p = static_cast<int>(f.size() / 4);
    double worst_margin = std::numeric_limits<double>::infinity();
    double min_fz = std::numeric_limits<double>::infinity();
    for (int i = 0; i < p; ++i) {
      const double fx = f(4 * i), fy = f(4 * i + 1), fz = f(4 * i + 2), mz = f(4 * i + 3);
      worst_margin = std::min(worst_margin, fz - std::hypot(fx, fy) / mu1_ - std::abs(mz) / mu2_);
      min_fz = std::min(min_fz, fz);
    }
    c.r[0] = max_abs(G * f + w_ext);
    c.r[1] = max_abs(J.transpose() * f - tau);
    c.r[2] = std::max(0.0, -worst_margin);
    c.r[3] = std::max(0.0, fmin_ - min_fz);
    c.r[4] = std::max(0.0, std::max((tau_min - tau).maxCoeff(), (tau - tau_max).maxCoeff()));
    return c;
  }

  int dims_changes() const {return inits_;}
  int m() const {return m_;}
  // What the batch stages (fast_batch.hpp) read.
  int cone_rows() const {return static_cast<int>(S_i_.rows());}
  const Vec & weights() const {return weights_;}
  const Vec & limits() const {return limits_;}
  double mu1_usage() const {return mu1_usage_;}
  const RowMat & S_i() const {return S_i_;}
  const Vec & b_i() const {return b_i_;}
  const Settings & settings() const {return s_;}
  double mu2_usage() const {return mu2_usage_;}

  bool passes(const Certificate & c) const
  {
    return c.finite && *std::max_element(c.r, c.r + 5) <= s_.certificate_tolerance;
  }

private:
  // One cycle: maps, build, solve_qp, certify (a warm answer off the certificate solved
  // again cold and certified again, as dispatch.solve does), then the planner's numbers.
  void run(
    Answer & a, const Kinematics & k, const Wrench & w_ext, const Vec & off,
    double time_left, Clock::time_point t0)
  {
    if (!maps(k, a.maps, a.message)) {
      return;
    }
    const auto t1 = Clock::now();
    a.t_maps = std::chrono::duration<double>(t1 - t0).count();

    QPData & qp = qp_data_;
    if (!build(a.maps.G, a.maps.J, w_ext, off, qp, a.message)) {
      return;
    }
    const auto t2 = Clock::now();
    a.t_build = std::chrono::duration<double>(t2 - t1).count();

    Clock::time_point deadline = Clock::time_point::max();
    const bool has_deadline = time_left >= 0.0;
    if (has_deadline) {
      // dispatch.PRIMARY_SHARE of the time left after the build, as the Python cycle.
      const double left = time_left - std::chrono::duration<double>(t2 - t0).count();
      deadline = t2 + std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double>(s_.primary_share * std::max(0.0, left)));
    }
    if (!solve_qp(qp, false, has_deadline, deadline, a)) {
      a.solve_time_s = a.t_solve = seconds_since(t2);
      return;
    }
    const auto t3 = Clock::now();
    a.solve_time_s = a.t_solve = std::chrono::duration<double>(t3 - t2).count();

    a.cert = certify(a.maps.G, a.maps.J, w_ext, qp.tau_min, qp.tau_max, a.tau, a.f);
    a.code = passes(a.cert) ? CERTIFIED : NOT_CERTIFIED;
    if (a.code == NOT_CERTIFIED && a.warm) {
      // dispatch.solve: a warm start that lands off the certificate is redone cold.
      if (!solve_qp(qp, true, has_deadline, deadline, a)) {
        a.t_solve = seconds_since(t2);
        return;
      }
      a.cert = certify(a.maps.G, a.maps.J, w_ext, qp.tau_min, qp.tau_max, a.tau, a.f);
      a.code = passes(a.cert) ? CERTIFIED : NOT_CERTIFIED;
    }
    a.t_certify = seconds_since(t3);
    if (a.code == CERTIFIED) {
      planner_metrics(a, off);
    }
  }

  // dispatch.planner_metrics: usage on the unreduced cone, max |tau + offset| / limit.
  void planner_metrics(Answer & a, const Vec & off) const
  {
    const int p = static_cast<int>(a.f.size() / 4);
    a.usage.resize(p);
    for (int i = 0; i < p; ++i) {
      const double fx = a.f(4 * i), fy = a.f(4 * i + 1), fz = a.f(4 * i + 2),
        mz = a.f(4 * i + 3);
      const double demand = std::hypot(fx, fy) / mu1_usage_ + std::abs(mz) / mu2_usage_;
      a.usage(i) = fz > 0.0 ? demand / fz : std::numeric_limits<double>::infinity();
    }
    a.max_torque_ratio = ((a.tau + off).cwiseAbs().array() / limits_.array()).maxCoeff();
  }

  static std::string solver_status(proxsuite::proxqp::QPSolverOutput s)
  {
    using O = proxsuite::proxqp::QPSolverOutput;
    switch (s) {
      case O::PROXQP_SOLVED: return "PROXQP_SOLVED";
      case O::PROXQP_MAX_ITER_REACHED: return "PROXQP_MAX_ITER_REACHED";
      case O::PROXQP_PRIMAL_INFEASIBLE: return "PROXQP_PRIMAL_INFEASIBLE";
      case O::PROXQP_DUAL_INFEASIBLE: return "PROXQP_DUAL_INFEASIBLE";
      case O::PROXQP_SOLVED_CLOSEST_PRIMAL_FEASIBLE: return "PROXQP_SOLVED_CLOSEST_PRIMAL_FEASIBLE";
      case O::PROXQP_NOT_RUN: return "PROXQP_NOT_RUN";
    }
    return "PROXQP_UNKNOWN";
  }

  // One daqp_quadprog call on the QP in daqp_A_, up_, lo_, H_, g_ (from the last
  // solved QP's active set when warm); DAQP's exit flag, its iterations in iterations.
  int daqp_run(bool warm, int limit, int & iterations)
  {
    const int n = m_, total = static_cast<int>(up_.size());
    sense_ = warm ? active_ : sense0_;  // DAQP may write to the array it is given
    DaqpProblem p{n, total, n, H_.data(), g_.data(), daqp_A_.data(), up_.data(), lo_.data(),
      sense_.data(), nullptr, 0, 0};
    DaqpResult res{x_.data(), lam_.data(), 0.0, 0.0, 0, 0, 0, 0.0, 0.0};
    DaqpSettings st = daqp_settings_;
    st.iter_limit = limit;
    quadprog_(&res, &p, &st);
    iterations = res.iter;
    return res.exitflag;
  }

  // daqp.DaqpSolver._kkt: the KKT violation of an answer DAQP calls optimal, else inf.
  double daqp_answer_kkt(int flag, int rows) const
  {
    if (flag != 1 || !x_.allFinite() || !lam_.allFinite()) {
      return std::numeric_limits<double>::infinity();
    }
    return daqp_kkt(
      H_.diagonal(), g_.data(), daqp_A_.data(), up_.data(), lo_.data(), x_.data(),
      lam_.data(), m_, rows);
  }

  // backends/proxsuite.kkt_violation
  double kkt_violation(const QPData & qp, const Vec & x, const Vec & y, const Vec & z) const
  {
    const int n_in = static_cast<int>(qp.C.rows());
    const auto z_C = z.head(n_in);
    const auto z_box = z.tail(x.size());
    const Vec grad = qp.H * x + qp.g;
    Vec residual = grad + qp.C.transpose() * z_C + z_box;
    if (qp.A.rows()) {
      residual += qp.A.transpose() * y;
    }
    const Vec slack = qp.u - qp.C * x;
    const Vec to_upper = qp.u_box - x, to_lower = x - qp.l_box;
    const double scale = std::max(1.0, max_abs(z));
    double dual = std::max(0.0, z_C.size() ? -z_C.minCoeff() : 0.0);
    for (int i = 0; i < x.size(); ++i) {
      const bool fu = std::isfinite(to_upper(i)), fl = std::isfinite(to_lower(i));
      if (!(fu && fl)) {
        dual = std::max(dual, std::abs(z_box(i)));
      }
      dual = std::max(dual, std::max(z_box(i), 0.0) * (fu ? to_upper(i) : 0.0));
      dual = std::max(dual, std::max(-z_box(i), 0.0) * (fl ? to_lower(i) : 0.0));
    }
    for (int i = 0; i < n_in; ++i) {
      dual = std::max(dual, std::abs(z_C(i) * slack(i)));
    }
    double primal = std::max({0.0, slack.size() ? -slack.minCoeff() : 0.0,
          -to_upper.minCoeff(), -to_lower.minCoeff()});
    if (qp.A.rows()) {
      primal = std::max(primal, max_abs(qp.A * x - qp.b));
    }
    return std::max({max_abs(residual) / std::max(1.0, max_abs(grad)), dual / scale, primal});
  }

  void init(const QPData & qp)
  {
    ++inits_;
    const int n = static_cast<int>(qp.H.rows()), n_eq = qp.n_eq();
    qp_ = std::make_unique<dense::QP<double>>(n, n_eq, static_cast<int>(qp.C.rows()), true,
                                               proxsuite::proxqp::HessianType::Diagonal,
                                               proxsuite::proxqp::DenseBackend::PrimalDualLDLT);
    auto & st = qp_->settings;
    st.eps_abs = s_.eps_abs;
    st.eps_rel = s_.eps_rel;
    st.max_iter = s_.max_iter;
    st.max_iter_in = s_.max_iter_in;
    st.eps_primal_inf = s_.eps_primal_inf;
    st.check_duality_gap = true;
    st.eps_duality_gap_abs = s_.eps_abs;
    st.eps_duality_gap_rel = 0.0;
    st.initial_guess = proxsuite::proxqp::InitialGuessStatus::NO_INITIAL_GUESS;
    if (n_eq) {
      qp_->init(qp.H, qp.g, qp.A, qp.b, qp.C, qp.l, qp.u, qp.l_box, qp.u_box, true);
    } else {
      qp_->init(qp.H, qp.g, proxsuite::nullopt, proxsuite::nullopt, qp.C, qp.l, qp.u,
        qp.l_box, qp.u_box, true);
    }
  }

  void update(const QPData & qp)
  {
    if (qp.n_eq()) {
      qp_->update(qp.H, qp.g, qp.A, qp.b, qp.C, qp.l, qp.u, qp.l_box, qp.u_box, false);
    } else {
      qp_->update(qp.H, qp.g, proxsuite::nullopt, proxsuite::nullopt, qp.C, qp.l, qp.u,
        qp.l_box, qp.u_box, false);
    }
  }

  // backends/proxsuite.TauQPSolver._solve_until: slices of outer iterations sized so
  // that even at max_iter_in inner iterations each ends by the deadline.
  int solve_until(bool has_deadline, Clock::time_point deadline, bool & stopped)
  {
    stopped = false;
    auto & st = qp_->settings;
    if (!has_deadline) {
      qp_->solve();
      return static_cast<int>(qp_->results.info.iter);
    }
    const int cap = s_.max_iter;
    int inner = 0, outer = 0;
    bool capped = false;
    for (;; ) {
      const double left = std::chrono::duration<double>(deadline - Clock::now()).count();
      if (left <= 0.0) {
        stopped = true;
        break;
      }
      const double per_outer = s_.max_iter_in * inner_s_;
      int k = static_cast<int>(std::max(1.0, std::floor(left / per_outer)));
      k = std::min(cap - outer, k);
      if (k != cap || capped) {
        st.max_iter = k;
        capped = true;
      }
      const auto ts = Clock::now();
      qp_->solve();
      const auto & info = qp_->results.info;
      const int iters = static_cast<int>(info.iter);
      inner += iters;
      outer += static_cast<int>(info.iter_ext);
      const double per_inner = seconds_since(ts) / std::max(1, iters);
      inner_s_ = std::max(per_inner, s_.estimate_decay * inner_s_);
      if (info.status != proxsuite::proxqp::QPSolverOutput::PROXQP_MAX_ITER_REACHED ||
        outer >= cap)
      {
        break;
      }
      st.initial_guess = proxsuite::proxqp::InitialGuessStatus::WARM_START_WITH_PREVIOUS_RESULT;
    }
    if (capped) {
      st.max_iter = cap;
    }
    return inner;
  }

  std::vector<int64_t> idx_v_;
  int m_ = 0;
  RowMat S_i_;
  Vec b_i_, weights_, limits_;
  double mu1_, mu2_, mu1_usage_, mu2_usage_, fmin_;
  bool warm_start_;
  Settings s_;
  std::unique_ptr<dense::QP<double>> qp_;
  QPData qp_data_;  // the build stage's output, its storage kept from cycle to cycle
  std::tuple<int, int, int> dims_{-1, -1, -1};
  double inner_s_ = 0.0;
  int inits_ = 0;
  // DAQP (use_daqp): its entry and settings, the QP in its form, the active sets.
  DaqpQuadprog quadprog_ = nullptr;
  DaqpSettings daqp_settings_{};
  double daqp_iteration_s_ = 0.0, iter_s_ = 0.0;
  RowMat daqp_A_;
  Mat H_;
  Vec g_, up_, lo_, x_, lam_;
  std::vector<int> sense0_, active_, sense_;
  bool have_active_ = false;
  std::unique_ptr<Tree> tree_;  // use_tree's; solve_q's kinematics
  // bind_contacts' arrays, for solve_bound.
  struct Bound
  {
    py::array_t<int64_t> fparent;
    Array Rf, tf, points, normals;
    py::array_t<bool> has_normal;
    Array tangents;
    py::array_t<bool> has_tangent;
  };
  std::unique_ptr<Bound> bound_;
  std::vector<double> oMf_, J6_;
};

py::array_t<double> to_array(const Vec & v)
{
  py::array_t<double> out(v.size());
  std::copy(v.data(), v.data() + v.size(), out.mutable_data());
  return out;
}

py::array_t<double> to_array(const RowMat & m)
{
  py::array_t<double> out({m.rows(), m.cols()});
  std::copy(m.data(), m.data() + m.size(), out.mutable_data());
  return out;
}

py::array_t<double> to_array(const Mat & m)
{
  return to_array(RowMat(m));
}

// rotations: p rows of 9 as (p, 3, 3).
py::array_t<double> to_rotations(const RowMat & r)
{
  py::array_t<double> out({r.rows(), py::ssize_t(3), py::ssize_t(3)});
  std::copy(r.data(), r.data() + r.size(), out.mutable_data());
  return out;
}

// The stages' Python entries copy their inputs in and their outputs out: they are for
// the parity tests, not the hot path. A wrong shape is a ValueError, not Eigen's assert.
void expect(bool ok, const std::string & what)
{
  if (!ok) {
    throw std::invalid_argument(what);
  }
}

RowMat as_matrix(const Array & a, py::ssize_t rows, py::ssize_t cols, const char * name)
{
  expect(
    a.ndim() == 2 && (rows < 0 || a.shape(0) == rows) && (cols < 0 || a.shape(1) == cols),
    std::string(name) + " of the wrong shape");
  return Eigen::Map<const RowMat>(a.data(), a.shape(0), a.shape(1));
}

Vec as_vector(const Array & a, py::ssize_t size, const char * name)
{
  expect(a.ndim() == 1 && a.shape(0) == size, std::string(name) + " of the wrong shape");
  return Eigen::Map<const Vec>(a.data(), size);
}

Wrench wrench(const Array & a)
{
  return as_vector(a, 6, "w_ext");
}


}  // namespace

#include "fast_batch.hpp"

// The module's name comes from the file that includes this one: fast_cycle.cpp
// (_fast_cycle, for any CPU) or fast_cycle_avx2.cpp (_fast_cycle_avx2, built with AVX2
// and FMA; compiled.py loads it only where the CPU has them).
PYBIND11_MODULE(FAST_CYCLE_MODULE, mod)
{
  mod.doc() = "The node's tau-QP cycle compiled (grasp_torque_opt.control.compiled).";
  // What compiled.py expects; a module built from an older source is not used.
  mod.attr("API") = 11;
  mod.attr("CERTIFIED") = CERTIFIED;
  mod.attr("NOT_HANDLED") = NOT_HANDLED;
  mod.attr("BAD_DATA") = BAD_DATA;
  mod.attr("NOT_SOLVED") = NOT_SOLVED;
  mod.attr("NOT_CERTIFIED") = NOT_CERTIFIED;
  mod.attr("TIMED_OUT") = TIMED_OUT;
  mod.attr("PROXSUITE_VERSION") = PROXSUITE_VERSION;

  py::class_<Settings>(mod, "Settings")
  .def(py::init<>())
  .def_readwrite("eps_abs", &Settings::eps_abs)
  .def_readwrite("eps_rel", &Settings::eps_rel)
  .def_readwrite("eps_primal_inf", &Settings::eps_primal_inf)
  .def_readwrite("max_iter", &Settings::max_iter)
  .def_readwrite("max_iter_in", &Settings::max_iter_in)
  .def_readwrite("kkt_tolerance", &Settings::kkt_tolerance)
  .def_readwrite("certificate_tolerance", &Settings::certificate_tolerance)
  .def_readwrite("qr_rtol", &Settings::qr_rtol)
  .def_readwrite("box_margin", &Settings::box_margin)
  .def_readwrite("inner_iteration_s", &Settings::inner_iteration_s)
  .def_readwrite("estimate_decay", &Settings::estimate_decay)
  .def_readwrite("primary_share", &Settings::primary_share);

  py::class_<Answer>(mod, "Answer")
  .def_readonly("code", &Answer::code)
  .def_readonly("message", &Answer::message)
  .def_property_readonly("tau", [](const Answer & a) {return to_array(a.tau);})
  .def_property_readonly("f", [](const Answer & a) {return to_array(a.f);})
  .def_property_readonly("G", [](const Answer & a) {return to_array(a.maps.G);})
  .def_property_readonly("J", [](const Answer & a) {return to_array(a.maps.J);})
  .def_property_readonly("positions", [](const Answer & a) {return to_array(a.maps.positions);})
  .def_property_readonly("rotations", [](const Answer & a) {return to_rotations(a.maps.rotations);})
  .def_property_readonly("usage", [](const Answer & a) {return to_array(a.usage);})
  .def_readonly("iterations", &Answer::iterations)
  .def_readonly("warm", &Answer::warm)
  .def_readonly("warm_solves", &Answer::warm_solves)
  .def_readonly("redone_cold", &Answer::redone_cold)
  .def_property_readonly("certificate", [](const Answer & a) {
      const Certificate & c = a.cert;
      return py::make_tuple(c.r[0], c.r[1], c.r[2], c.r[3], c.r[4], c.finite);
    })
  .def_readonly("max_torque_ratio", &Answer::max_torque_ratio)
  .def_readonly("solve_time_s", &Answer::solve_time_s)
  .def_property_readonly("timings", [](const Answer & a) {
      return py::make_tuple(a.t_maps, a.t_build, a.t_solve, a.t_certify);
    })
  .def_property_readonly("parts", [](const Answer & a) {
      const Certificate & c = a.cert;
      return py::make_tuple(
        to_array(a.tau), to_array(a.f), to_array(a.maps.G), to_array(a.maps.J),
        to_array(a.maps.positions), to_rotations(a.maps.rotations), to_array(a.usage),
        py::make_tuple(c.r[0], c.r[1], c.r[2], c.r[3], c.r[4], c.finite),
        py::make_tuple(a.t_maps, a.t_build, a.t_solve, a.t_certify));
    }, "(tau, f, G, J, positions, rotations, usage, certificate, timings) in one call.");

  py::class_<FastCycle>(mod, "FastCycle")
  .def(py::init<py::array_t<int64_t>, Array, Array, Array, Array, double, double, double,
    double, double, bool, const Settings &>(),
         py::arg("idx_v"), py::arg("S_i"), py::arg("b_i"), py::arg("weights"),
         py::arg("limits"), py::arg("mu1"), py::arg("mu2"), py::arg("mu1_usage"),
         py::arg("mu2_usage"), py::arg("min_normal_force"), py::arg("warm_start"),
         py::arg("settings"))
  .def("solve", &FastCycle::solve, py::arg("oMf"), py::arg("J6"), py::arg("points"),
         py::arg("normals"), py::arg("has_normal"), py::arg("tangents"),
         py::arg("has_tangent"), py::arg("c"), py::arg("w_ext"), py::arg("offset"),
         py::arg("time_left"))
  .def("use_daqp", &FastCycle::use_daqp, py::arg("quadprog"), py::arg("defaults"),
    py::arg("primal_tol"), py::arg("iter_limit"), py::arg("eq_reduction"),
    py::arg("iteration_s"), "Solve with DAQP's C entry (its addresses) instead of ProxSuite.")
  .def("use_tree", &FastCycle::use_tree, py::arg("parents"), py::arg("kinds"),
    py::arg("axes"), py::arg("Rp"), py::arg("tp"), py::arg("idx_q"), py::arg("idx_v"),
    py::arg("nq"), py::arg("nv"),
    "Compute the contact links' kinematics from the hand's tree (for solve_q).")
  .def("solve_q", &FastCycle::solve_q, py::arg("q"), py::arg("fparent"), py::arg("Rf"),
    py::arg("tf"), py::arg("points"), py::arg("normals"), py::arg("has_normal"),
    py::arg("tangents"), py::arg("has_tangent"), py::arg("c"), py::arg("w_ext"),
    py::arg("offset"), py::arg("time_left"))
  .def("bind_contacts", &FastCycle::bind_contacts, py::arg("fparent"), py::arg("Rf"),
    py::arg("tf"), py::arg("points"), py::arg("normals"), py::arg("has_normal"),
    py::arg("tangents"), py::arg("has_tangent"),
    "Hold the contact list of the cycles to come (solve_q's arrays), for solve_bound.")
  .def("solve_bound", &FastCycle::solve_bound, py::arg("q"), py::arg("c"), py::arg("w_ext"),
    py::arg("offset"), py::arg("time_left"),
    "solve_q on the contacts of bind_contacts.")
  .def_property_readonly("uses_tree", &FastCycle::uses_tree)
  .def_property_readonly("uses_daqp", &FastCycle::uses_daqp)
  .def_property_readonly("inits", &FastCycle::dims_changes)
  // The four stages of solve() one by one, on given inputs (the parity tests).
  .def("maps", [](const FastCycle & fc, Array oMf, Array J6, Array points, Array normals,
    py::array_t<bool> has_normal, Array tangents, py::array_t<bool> has_tangent, Array c) {
      Kinematics k;
      Maps out;
      std::string why;
      expect(
        fc.borrow(oMf, J6, points, normals, has_normal, tangents, has_tangent, c, k, why) &&
        fc.maps(k, out, why), why);
      py::dict d;
      d["G"] = to_array(out.G);
      d["J"] = to_array(out.J);
      d["positions"] = to_array(out.positions);
      d["rotations"] = to_rotations(out.rotations);
      return d;
    }, py::arg("oMf"), py::arg("J6"), py::arg("points"), py::arg("normals"),
    py::arg("has_normal"), py::arg("tangents"), py::arg("has_tangent"), py::arg("c"),
    "The maps stage: contact frames, G and J (ValueError where it hands back).")
  .def("build", [](const FastCycle & fc, Array G, Array J, Array w_ext, Array offset) {
      const RowMat Gm = as_matrix(G, 6, -1, "G");
      const RowMat Jm = as_matrix(J, Gm.cols(), fc.m(), "J");
      const Vec off = offset.size() ? as_vector(offset, fc.m(), "offset") : Vec(Vec::Zero(fc.m()));
      QPData qp;
      std::string why;
      expect(fc.build(Gm, Jm, wrench(w_ext), off, qp, why), why);
      py::dict d;
      d["H"] = to_array(qp.H);
      d["g"] = to_array(qp.g);
      d["A"] = to_array(qp.A);
      d["b"] = to_array(qp.b);
      d["C"] = to_array(qp.C);
      d["l"] = to_array(qp.l);
      d["u"] = to_array(qp.u);
      d["l_box"] = to_array(qp.l_box);
      d["u_box"] = to_array(qp.u_box);
      d["M1"] = to_array(RowMat(qp.M1()));
      d["M2"] = to_array(RowMat(qp.M2()));
      d["w"] = to_array(qp.w);
      d["tau_min"] = to_array(qp.tau_min);
      d["tau_max"] = to_array(qp.tau_max);
      return d;
    }, py::arg("G"), py::arg("J"), py::arg("w_ext"), py::arg("offset"),
    "The build stage: the tau-QP of G and J (ValueError where it hands back).")
  .def("solve_qp", [](FastCycle & fc, Array H, Array g, Array A, Array b, Array C, Array u,
    Array l_box, Array u_box, Array M1, Array M2, Array w, bool cold, double time_left) {
      const int m = fc.m();
      QPData qp;
      qp.H = as_matrix(H, m, m, "H");
      qp.g = as_vector(g, m, "g");
      qp.A = as_matrix(A, -1, m, "A");
      qp.b = as_vector(b, qp.A.rows(), "b");
      qp.C = as_matrix(C, -1, m, "C");
      qp.u = as_vector(u, qp.C.rows(), "u");
      qp.l.setConstant(qp.C.rows(), -std::numeric_limits<double>::infinity());
      qp.l_box = as_vector(l_box, m, "l_box");
      qp.u_box = as_vector(u_box, m, "u_box");
      const RowMat M1m = as_matrix(M1, -1, 6, "M1");
      qp.pinv.resize(M1m.rows(), 6 + m);
      qp.pinv.leftCols(6) = M1m;
      qp.pinv.rightCols(m) = as_matrix(M2, M1m.rows(), m, "M2");
      qp.w = as_vector(w, 6, "w");
      const bool has_deadline = time_left >= 0.0;
      const auto deadline = has_deadline ? Clock::now() +
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(time_left)) :
      Clock::time_point::max();
      Answer a;
      const bool solved = fc.solve_qp(qp, cold, has_deadline, deadline, a);
      py::dict d;
      d["solved"] = solved;
      d["code"] = a.code;
      d["message"] = a.message;
      d["tau"] = to_array(a.tau);
      d["f"] = to_array(a.f);
      d["iterations"] = a.iterations;
      d["warm"] = a.warm;
      d["warm_solves"] = a.warm_solves;
      d["redone_cold"] = a.redone_cold;
      return d;
    }, py::arg("H"), py::arg("g"), py::arg("A"), py::arg("b"), py::arg("C"), py::arg("u"),
    py::arg("l_box"), py::arg("u_box"), py::arg("M1"), py::arg("M2"), py::arg("w"),
    py::arg("cold") = false, py::arg("time_left") = -1.0,
    "The solve stage on this cycle's QP, ProxSuite or DAQP (warm from its last solve).")
  .def("certify", [](const FastCycle & fc, Array G, Array J, Array w_ext, Array tau_min,
    Array tau_max, Array tau, Array f) {
      const int m = fc.m();
      const RowMat Gm = as_matrix(G, 6, -1, "G");
      const Certificate c = fc.certify(
        Gm, as_matrix(J, Gm.cols(), m, "J"), wrench(w_ext), as_vector(tau_min, m, "tau_min"),
        as_vector(tau_max, m, "tau_max"), as_vector(tau, m, "tau"), as_vector(f, Gm.cols(), "f"));
      return py::make_tuple(c.r[0], c.r[1], c.r[2], c.r[3], c.r[4], c.finite);
    }, py::arg("G"), py::arg("J"), py::arg("w_ext"), py::arg("tau_min"), py::arg("tau_max"),
    py::arg("tau"), py::arg("f"),
    "The certify stage: (equilibrium, torque, cone, normal_force, limit, finite).")
  // Batch scoring (fast_batch.hpp, grasp_torque_opt.methods.batch).
  .def("build_batch", &build_batch, py::arg("oMf"), py::arg("J6"), py::arg("points"),
    py::arg("normals"), py::arg("has_normal"), py::arg("tangents"), py::arg("has_tangent"),
    py::arg("c"), py::arg("w_ext"),
    "The maps and build stages of N candidates, each tau-QP in DAQP's form.")
  .def("finish_batch", &finish_batch, py::arg("G"), py::arg("J"), py::arg("w_ext"),
    py::arg("M1w"), py::arg("M2"), py::arg("A"), py::arg("bupper"), py::arg("blower"),
    py::arg("x"), py::arg("lam"), py::arg("solved"), py::arg("kkt_tolerance"),
    "KKT check, wrenches, certificate and planner numbers of N DAQP answers.")
  .def("lp_finish_batch", &lp_finish_batch, py::arg("G"), py::arg("J"), py::arg("cand"),
    py::arg("loads"), py::arg("scale"), py::arg("A"), py::arg("blower"), py::arg("bupper"),
    py::arg("c"), py::arg("x"), py::arg("lam"), py::arg("ok"), py::arg("kkt_tolerance"),
    py::arg("alpha_max"),
    "KKT check, alpha and certificate of K capacity-LP answers.")
  .def("capacity_batch", &capacity_batch, py::arg("quadprog"), py::arg("defaults"),
    py::arg("G"), py::arg("J"), py::arg("W"), py::arg("axes"), py::arg("S"), py::arg("bl"),
    py::arg("bu"), py::arg("sense"), py::arg("bl0"), py::arg("bu0"), py::arg("sense0"),
    py::arg("primal_tol"), py::arg("iter_limit"), py::arg("eps_prox"),
    py::arg("kkt_tolerance"), py::arg("alpha_max"), py::arg("vertex") = true,
    "The capacity LPs of N candidates, solved by the vertex method or DAQP and checked.");
  py::class_<TreePoints>(mod, "TreePoints")
  .def(py::init([](py::array_t<int64_t> parents, py::array_t<int64_t> kinds, Array axes,
    Array Rp, Array tp, py::array_t<int64_t> idx_q, py::array_t<int64_t> idx_v, int64_t nq,
    int64_t nv, py::array_t<int64_t> fparent, Array Rf, Array tf, Array local, int64_t base,
    Array Rb, Array tb) {
      const py::ssize_t p = fparent.size();
      expect(
        Rf.size() == 9 * p && tf.size() == 3 * p && local.size() == 3 * p &&
        Rb.size() == 9 && tb.size() == 3, "joint or frame tables of the wrong shape");
      return TreePoints(
        tree_of(parents, kinds, axes, Rp, tp, idx_q, idx_v, nq, nv), p, fparent.data(),
        Rf.data(), tf.data(), local.data(), base, Rb.data(), tb.data());
    }), py::arg("parents"), py::arg("kinds"), py::arg("axes"), py::arg("Rp"), py::arg("tp"),
    py::arg("idx_q"), py::arg("idx_v"), py::arg("nq"), py::arg("nv"), py::arg("fparent"),
    py::arg("Rf"), py::arg("tf"), py::arg("local"), py::arg("base"), py::arg("Rb"),
    py::arg("tb"))
  .def("points", [](TreePoints & tp, Array q) {
      expect(q.size() == tp.nq(), "q of the wrong shape");
      TreePoints::Points out;
      tp.points(q.data(), out);
      return to_array(RowMat(out));
    }, py::arg("q"), "The points at configuration q, (p, 3).")
  .def("estimate", [](TreePoints & tp, Array q, Array p0) {
      expect(q.size() == tp.nq(), "q of the wrong shape");
      expect(p0.ndim() == 2 && p0.shape(0) == tp.size() && p0.shape(1) == 3,
        "p0 of the wrong shape");
      TreePoints::Points p;
      tp.points(q.data(), p);
      TreePoints::M3 R;
      TreePoints::V3 t;
      Vec residuals;
      TreePoints::fit(Eigen::Map<const TreePoints::Points>(p0.data(), tp.size(), 3), p, R, t,
        residuals);
      return py::make_tuple(to_array(RowMat(R)), to_array(Vec(t)), to_array(RowMat(p)),
        to_array(residuals));
    }, py::arg("q"), py::arg("p0"),
    "(R, t, points, residuals): the rigid motion carrying p0 to the points at q.");
  mod.def("loop_step", [](TreePoints & tp, Array q, Array p0, Array origin, Array slow,
    Array rate, Array error, Array integral, double dt, Array gains, double weight,
    double lever, bool certified, bool at_limit) {
      expect(q.size() == tp.nq(), "q of the wrong shape");
      expect(p0.ndim() == 2 && p0.shape(0) == tp.size() && p0.shape(1) == 3,
        "p0 of the wrong shape");
      expect(
        origin.size() == 3 && slow.ndim() == 1 && rate.size() == 6 && error.size() == 6 &&
        integral.size() == 6, "loop state of the wrong shape");
      expect(gains.size() == LoopSettings::size, "gains of the wrong size");
      expect(dt > 0.0, "dt must be positive");
      LoopState st;
      st.slow = Eigen::Map<const Vec>(slow.data(), slow.size());
      st.rate = Eigen::Map<const Vec6>(rate.data());
      st.error = Eigen::Map<const Vec6>(error.data());
      st.integral = Eigen::Map<const Vec6>(integral.data());
      const Frozen frozen = loop_step(
        tp, q.data(), Eigen::Map<const TreePoints::Points>(p0.data(), tp.size(), 3),
        Eigen::Map<const Tree::V3>(origin.data()), dt, LoopSettings(gains.data()), weight,
        lever, certified, at_limit, st);
      return py::make_tuple(
        to_array(Vec(st.wrench)), to_array(Vec(st.integral)), to_array(Vec(st.error)),
        to_array(Vec(st.rate)), to_array(st.residual), to_array(st.slip), to_array(st.slow),
        static_cast<int>(frozen));
    }, py::arg("points"), py::arg("q"), py::arg("p0"), py::arg("origin"), py::arg("slow"),
    py::arg("rate"), py::arg("error"), py::arg("integral"), py::arg("dt"), py::arg("gains"),
    py::arg("weight"), py::arg("lever"), py::arg("certified"), py::arg("at_limit"),
    "(wrench, integral, error, rate, residual, slip, slow, frozen): one engaged step of "
    "the object loop.");
  // Three checks of every cycle, each the same answer as its numpy form in one call
  // instead of four or five numpy calls: control/cycle.checked_command_numpy,
  // control/rates.within_step_numpy and the numpy branch of
  // control/inputs/joint_states.JointStates.check.
  mod.def("gate_command", [](Array tau, Array offset, Array limits, double fraction) {
      expect(
        tau.ndim() == 1 && limits.ndim() == 1 && tau.size() == limits.size() &&
        (offset.size() == 0 || offset.size() == tau.size()), "gate_command: sizes differ");
      const py::ssize_t n = tau.size();
      const double * t = tau.data();
      const double * g = offset.size() ? offset.data() : nullptr;
      const double * lim = limits.data();
      py::array_t<double> cmd(n);
      double * c = cmd.mutable_data();
      bool finite = true, at_limit = false;
      py::ssize_t worst = -1;
      double most = 0.0;
      for (py::ssize_t i = 0; i < n; ++i) {
        c[i] = g ? t[i] + g[i] : t[i];
        const double a = std::abs(c[i]);
        finite = finite && std::isfinite(c[i]);
        at_limit = at_limit || a >= fraction * lim[i];
        const double over = a - lim[i];  // > 0 exactly when a > lim[i]; NaN: not
        if (over > 0.0 && (worst == -1 || over > most)) {
          worst = i;
          most = over;
        }
      }
      return py::make_tuple(cmd, finite ? worst : py::ssize_t{-2}, at_limit);
    }, py::arg("tau"), py::arg("offset"), py::arg("limits"), py::arg("fraction"),
    "(tau + offset, -1 if within the limits, -2 if not finite, else the joint most over "
    "its limit, whether a joint is at fraction of its limit or more).");
  mod.def("within_step", [](Array start, Array target, double step) {
      if (start.ndim() != target.ndim() || start.size() != target.size()) {
        return false;
      }
      const double * a = start.data();
      const double * b = target.data();
      for (py::ssize_t i = 0; i < start.size(); ++i) {
        if (!(std::abs(b[i] - a[i]) <= step)) {
          return false;  // NaN as well
        }
      }
      return true;
    }, py::arg("start"), py::arg("target"), py::arg("step"),
    "Whether no value of target is farther than step from start's (False for NaN).");
  mod.def("take_positions", [](Array positions, py::array_t<std::int64_t> pick, Array low,
    Array high, py::array_t<double> q, py::array_t<std::int64_t> put) {
      const py::ssize_t n = pick.size(), size = positions.size(), nq = q.size();
      expect(
        low.size() == n && high.size() == n && put.size() == n && q.ndim() == 1 &&
        q.writeable(), "take_positions: sizes differ");
      const double * p = positions.data();
      const std::int64_t * from = pick.data();
      const std::int64_t * to = put.data();
      for (py::ssize_t k = 0; k < n; ++k) {
        expect(from[k] >= 0 && from[k] < size && to[k] >= 0 && to[k] < nq,
          "take_positions: an index out of range");
        const double v = p[from[k]];
        if (!(v >= low.data()[k] && v <= high.data()[k])) {
          return false;  // NaN as well; q untouched
        }
      }
      auto out = q.mutable_unchecked<1>();
      for (py::ssize_t k = 0; k < n; ++k) {
        out(to[k]) = p[from[k]];
      }
      return true;
    }, py::arg("positions"), py::arg("pick"), py::arg("low"), py::arg("high"),
    py::arg("q").noconvert(), py::arg("put"),
    "Put positions[pick] into q[put] if each lies within [low, high] (True), else "
    "leave q as it is (False; NaN is not within).");
  mod.def("rotation_vector", [](Array R) {
      expect(R.ndim() == 2 && R.shape(0) == 3 && R.shape(1) == 3, "R of the wrong shape");
      return to_array(Vec(rotation_vector(Eigen::Map<const Tree::M3>(R.data()))));
    }, py::arg("R"), "The rotation vector of a rotation matrix (pinocchio.log3).");
  mod.def("rigid_fit", [](Array p0, Array p) {
      expect(p0.ndim() == 2 && p0.shape(1) == 3 && p.ndim() == 2 && p.shape(1) == 3 &&
        p.shape(0) == p0.shape(0) && p.shape(0) > 0, "p0 or p of the wrong shape");
      TreePoints::M3 R;
      TreePoints::V3 t;
      Vec residuals;
      TreePoints::fit(Eigen::Map<const TreePoints::Points>(p0.data(), p0.shape(0), 3),
        Eigen::Map<const TreePoints::Points>(p.data(), p.shape(0), 3), R, t, residuals);
      return py::make_tuple(to_array(RowMat(R)), to_array(Vec(t)), to_array(residuals));
    }, py::arg("p0"), py::arg("p"),
    "(R, t, residuals): Kabsch's rigid motion carrying points p0 (n, 3) to p.");
  mod.def("kinematics_batch", &kinematics_batch, py::arg("Q"), py::arg("parents"),
    py::arg("kinds"), py::arg("axes"), py::arg("Rp"), py::arg("tp"), py::arg("idx_q"),
    py::arg("idx_v"), py::arg("fparent"), py::arg("Rf"), py::arg("tf"), py::arg("nv"),
    "Frame placements and LOCAL_WORLD_ALIGNED Jacobians of N configurations of a tree.");
}

#endif  // FAST_CYCLE_HPP_
