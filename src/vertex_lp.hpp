// Copyright 2026 grasp_torque_opt developers
//
// Use of this source code is governed by a BSD-style
// license that can be found in the LICENSE file or at
// https://developers.google.com/open-source/licenses/bsd
//
// SPDX-License-Identifier: BSD-3-Clause

// A small dense LP solved from a feasible point by a primal active-set (vertex) method:
// the capacity LPs of the batch (fast_batch.hpp, capacity_batch), which share their rows
// and a feasible point (the certified zero-load wrenches at alpha = 0) and differ in one
// column, alpha's. Written here, not taken from a library, because what makes it fast
// is that shared start: each LP starts at the zero-load vertex and needs a few pivots of
// an n x n working set (n = 11 on the Allegro, its equalities eliminated) where DAQP,
// from scratch, takes about fifty proximal-point iterations. No answer is trusted
// alone: the caller checks the KKT conditions with these multipliers and certifies the
// primal answer, and DAQP solves any LP this does not answer.

#ifndef VERTEX_LP_HPP_
#define VERTEX_LP_HPP_

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace
{

// minimize c'x subject to R x <= r, from a feasible x0 (the capacity LPs have their
// equalities eliminated first). The working set always holds n rows, B x = b_W:
// inequalities at equality and, where these do not make n independent rows, artificial
// rows x_j = x0_j, which are dropped
// as soon as their multiplier is not zero (either sign). Each pivot drops the row with
// the most negative multiplier (Bland's rule after a run of degenerate pivots), moves
// along the edge it frees to the first row it meets (the ratio test) and updates B's
// inverse and the multipliers by Sherman-Morrison; the answer and its multipliers are
// solved again from B at the end.
//
// N: the number of unknowns where it is known when compiling (fixed-size Eigen types:
// about 10% less time on the Allegro's 11), or Eigen::Dynamic.
template<int N>
struct VertexLPT
{
  enum Kind { INEQUALITY, ARTIFICIAL };
  enum Status { OPTIMAL, UNBOUNDED, FAILED };
  using VecN = Eigen::Matrix<double, N, 1>;
  using MatN = Eigen::Matrix<double, N, N>;
  using RowMatN = Eigen::Matrix<double, N, N, Eigen::RowMajor>;

  // Where the method stands: the working set (B's rows, their right-hand sides, what
  // each is and its row index, B's inverse), x and the slack of every inequality (+inf
  // for those in the working set, which the ratio test then never takes). A copy
  // restarts the method from here.
  struct State
  {
    RowMatN B;
    MatN Binv;
    VecN b, x;
    Vec slack;
    std::vector<Kind> kind;
    std::vector<int> index;
  };

  Eigen::Matrix<double, Eigen::Dynamic, N> R;  // column-major: R d as axpys
  Eigen::Matrix<double, N, Eigen::Dynamic> Rt;  // R's transpose (start()): rows contiguous
  Vec r;
  State s;
  VecN mu, d, u, v, w;
  Vec Rd, ratio;
  int iterations = 0;

  // Replace working row q by a (right-hand side rhs) without moving: B's inverse by
  // Sherman-Morrison, with w = a' B^-1 (w(q) != 0: the rows stay independent).
  void replace(int q, const Eigen::Ref<const VecN> & a, double rhs)
  {
    u = s.Binv.col(q) / w(q);
    v = w;
    v(q) -= 1.0;
    s.Binv.noalias() -= u * v.transpose();
    s.B.row(q) = a.transpose();
    s.b(q) = rhs;
  }

  // Bring inequality i (row a) into the working set in place of the artificial row it
  // depends on most; false when it depends on none enough (then it stays out).
  bool enter(const Eigen::Ref<const VecN> & a, double rhs, int i)
  {
    w.noalias() = s.Binv.transpose() * a;
    int q = -1;
    double best = 1e-7 * std::max(1.0, a.cwiseAbs().maxCoeff());
    for (int j = 0; j < static_cast<int>(s.kind.size()); ++j) {
      if (s.kind[j] == ARTIFICIAL && std::abs(w(j)) > best) {
        best = std::abs(w(j));
        q = j;
      }
    }
    if (q < 0) {
      return false;
    }
    replace(q, a, rhs);
    s.kind[q] = INEQUALITY;
    s.index[q] = i;
    return true;
  }

  // The working set at x0: the inequalities within tight (relative) of equality, each in
  // order where it is independent of those before.
  void start(const VecN & x0, double tight)
  {
    const int n = static_cast<int>(x0.size()), nr = static_cast<int>(R.rows());
    s.B = RowMatN::Identity(n, n);
    s.Binv = MatN::Identity(n, n);
    s.b = x0;
    s.x = x0;
    s.kind.assign(n, ARTIFICIAL);
    s.index.assign(n, -1);
    Rt = R.transpose();
    s.slack = r - R * s.x;
    for (int i = 0; i < nr; ++i) {
      const double scale = std::max(1.0, std::abs(r(i)));
      if (s.slack(i) <= tight * scale && enter(Rt.col(i), r(i), i)) {
        s.slack(i) = std::numeric_limits<double>::infinity();
      }
    }
  }

  // Column j of R set to rc as it was when a saved State was made (the working set is
  // not touched: assign that State after this).
  void reset_column(int j, const Vec & rc)
  {
    R.col(j) = rc;
    Rt.row(j) = rc.transpose();
  }

  // Column j of R set to rc at a point where x_j = 0 (x and the slacks stay as they are):
  // the working set's B follows, its inverse by Sherman-Morrison.
  void set_column(int j, const Vec & rc)
  {
    const int n = static_cast<int>(s.x.size());
    u = VecN::Zero(n);
    for (int q = 0; q < n; ++q) {
      if (s.kind[q] == INEQUALITY) {
        u(q) = rc(s.index[q]) - R(s.index[q], j);
      }
    }
    reset_column(j, rc);
    s.B.col(j) += u;
    w.noalias() = s.Binv * u;
    v = s.Binv.row(j).transpose();
    s.Binv.noalias() -= w * (v.transpose() / (1.0 + v.dot(u)));
  }

  // Minimize c'x from the state s, at most iter_limit pivots.
  Status iterate(const VecN & c, int iter_limit)
  {
    const int n = static_cast<int>(s.x.size()), nr = static_cast<int>(R.rows());
    const double inf = std::numeric_limits<double>::infinity();
    ratio.resize(nr);
    iterations = 0;
    const double dual_tol = 1e-12, pivot_tol = 1e-9;
    int degenerate = 0;
    mu.noalias() = -(s.Binv.transpose() * c);
    for (; iterations < iter_limit; ++iterations) {
      const bool bland = degenerate > 2 * n;
      int q = -1;
      double best = 0.0;
      for (int j = 0; j < n; ++j) {
        const double gain = s.kind[j] == INEQUALITY ? -mu(j) : std::abs(mu(j));
        if (!(gain > dual_tol)) {
          continue;
        }
        if (bland) {
          q = j;
          break;
        }
        const double rate = gain * gain / s.Binv.col(j).squaredNorm();  // steepest edge
        if (rate > best) {
          best = rate;
          q = j;
        }
      }
      if (q < 0) {
        return finish(c) ? OPTIMAL : FAILED;
      }
      d = (mu(q) > 0.0 ? 1.0 : -1.0) * s.Binv.col(q);
      Rd.noalias() = R * d;
      // The ratio test over the rows not in the working set that d moves towards; of
      // rows tied at the smallest step, the one d meets most squarely (Bland: the first).
      // A loop without branches, which the compiler vectorizes (setup.py's
      // -fno-trapping-math): a row d does not move towards is read as +inf.
      const double * sl = s.slack.data(), * rd = Rd.data();
      double * ra = ratio.data();
      for (int i = 0; i < nr; ++i) {
        const bool toward = rd[i] > pivot_tol;
        const double num = toward ? std::max(sl[i], 0.0) : inf, den = toward ? rd[i] : 1.0;
        ra[i] = num / den;
      }
      const double step = ratio.minCoeff();
      int p = -1;
      double size = 0.0;
      for (int i = 0; std::isfinite(step) && i < nr; ++i) {
        if (ra[i] <= step && rd[i] > size) {
          p = i;
          size = rd[i];
          if (bland) {
            break;
          }
        }
      }
      if (p < 0) {
        return UNBOUNDED;
      }
      degenerate = step > 0.0 ? 0 : degenerate + 1;
      if (s.kind[q] == INEQUALITY) {
        s.slack(s.index[q]) = 0.0;  // leaves the working set, at equality until the step
      }
      s.x.noalias() += step * d;
      s.slack.noalias() -= step * Rd;
      // Row p in for row q; the multipliers follow B's inverse: mu' = mu - v mu_q / w_q.
      w.noalias() = s.Binv.transpose() * Rt.col(p);
      const double dual = mu(q) / w(q);
      replace(q, Rt.col(p), r(p));
      mu.noalias() -= dual * v;
      s.kind[q] = INEQUALITY;
      s.index[q] = p;
      s.slack(p) = std::numeric_limits<double>::infinity();
    }
    return FAILED;
  }

  // The answer solved again from B, x = B^-1 b, and its multipliers (c + B' mu = 0), each
  // with a step of iterative refinement against the updates' rounding; false if either
  // is not finite.
  bool finish(const VecN & c)
  {
    s.x.noalias() = s.Binv * s.b;
    u.noalias() = s.b - s.B * s.x;
    s.x.noalias() += s.Binv * u;
    mu.noalias() = -(s.Binv.transpose() * c);
    u.noalias() = -c - s.B.transpose() * mu;
    mu.noalias() += s.Binv.transpose() * u;
    return s.x.allFinite() && mu.allFinite();
  }
};

}  // namespace

#endif  // VERTEX_LP_HPP_
