// Copyright 2026 grasp_torque_opt developers
//
// Use of this source code is governed by a BSD-style
// license that can be found in the LICENSE file or at
// https://developers.google.com/open-source/licenses/bsd
//
// SPDX-License-Identifier: BSD-3-Clause

// One engaged step of the object loop (control/object_loop.ObjectLoop.update once its
// reference is taken, whose numpy twin this is): the object's motion from the fingertips
// (TreePoints), the slip evidence, the error's filtered rate, the integral with its
// anti-windup, and the restoring wrench, bounded. In numpy these are some thirty calls
// on 6-vectors a cycle, each costing more in dispatch than its arithmetic. Included by
// fast_cycle.hpp.

#ifndef OBJECT_LOOP_HPP_
#define OBJECT_LOOP_HPP_

#include <Eigen/Core>

#include <algorithm>
#include <cmath>

#include "tree_kinematics.hpp"

namespace
{

using Vec6 = Eigen::Matrix<double, 6, 1>;

// The loop's settings (control/object_loop.LoopGains.packed, in that order).
struct LoopSettings
{
  Vec6 k, d, ki;
  double slip_memory, velocity_filter, unwind_time, slip_residual;
  double max_integral_ratio, max_force_ratio;
  static constexpr int size = 24;

  explicit LoopSettings(const double * g)
  : k(Eigen::Map<const Vec6>(g)), d(Eigen::Map<const Vec6>(g + 6)),
    ki(Eigen::Map<const Vec6>(g + 12)), slip_memory(g[18]), velocity_filter(g[19]),
    unwind_time(g[20]), slip_residual(g[21]), max_integral_ratio(g[22]),
    max_force_ratio(g[23]) {}
};

// The rotation vector of R (pinocchio.log3): angle in [0, pi] times the axis. Its angle
// by atan2 (exact near 0 and pi); near pi, where sin is small, the axis from R's
// symmetric part, its sign from the skew part.
inline Eigen::Vector3d rotation_vector(const Tree::M3 & R)
{
  const Eigen::Vector3d v(
    0.5 * (R(2, 1) - R(1, 2)), 0.5 * (R(0, 2) - R(2, 0)), 0.5 * (R(1, 0) - R(0, 1)));
  const double c = std::clamp(0.5 * (R.trace() - 1.0), -1.0, 1.0);
  const double s = v.norm();
  const double theta = std::atan2(s, c);
  if (c > 0.0) {
    // theta / sin(theta): its series below 1e-4 rad (exact to double there).
    const double f = theta < 1e-4 ? 1.0 + theta * theta / 6.0 : theta / s;
    return f * v;
  }
  // R + R^T = 2 c I + 2 (1 - c) a a^T: the column of the largest diagonal.
  const Eigen::Matrix3d B = 0.5 * (R + R.transpose()) - c * Eigen::Matrix3d::Identity();
  int i = 0;
  B.diagonal().maxCoeff(&i);
  Eigen::Vector3d a = B.col(i) / std::sqrt(std::max(B(i, i) * (1.0 - c), 1e-300));
  a.normalize();
  if (a.dot(v) < 0.0) {
    a = -a;
  }
  return theta * a;
}

// The factors (force, moment) that scale a wrench to at most `force` and `force * lever`
// (object_loop.scales).
inline void wrench_scales(const Vec6 & w, double force, double lever, double & s_f, double & s_m)
{
  const double norm_f = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
  const double norm_m = std::sqrt(w[3] * w[3] + w[4] * w[4] + w[5] * w[5]);
  const double limit = force * lever;
  s_f = norm_f > force ? force / norm_f : 1.0;
  s_m = norm_m > limit ? limit / norm_m : 1.0;
}

inline Vec6 bounded_wrench(Vec6 w, double force, double lever)
{
  double s_f = 1.0, s_m = 1.0;
  wrench_scales(w, force, lever, s_f, s_m);
  if (s_f != 1.0) {
    w.head<3>() *= s_f;
  }
  if (s_m != 1.0) {
    w.tail<3>() *= s_m;
  }
  return w;
}

// Why the integral did not move (object_loop.FROZEN's order).
enum class Frozen : int {moved = 0, not_certified = 1, at_limit = 2, slips = 3};

// The loop's state across cycles (the ObjectLoop's arrays of the same names).
struct LoopState
{
  Eigen::VectorXd slow, residual, slip;
  Vec6 rate, error, integral, wrench;
};

// One engaged step: the object at q (reference points p0, carried by the estimate's
// rigid motion, about `origin`), dt since the last step, `previous` the last cycle's
// outcome. Updates `st` and returns why the integral was frozen.
inline Frozen loop_step(
  TreePoints & tp, const double * q, const TreePoints::Points & p0, const Tree::V3 & origin,
  double dt, const LoopSettings & g, double weight, double lever, bool certified,
  bool at_limit, LoopState & st)
{
  TreePoints::Points p;
  tp.points(q, p);
  TreePoints::M3 R;
  TreePoints::V3 t;
  Eigen::VectorXd residual;
  TreePoints::fit(p0, p, R, t, residual);
  if (st.slow.size() != residual.size()) {
    st.slow = residual;
  }
  st.slip = (residual - st.slow).cwiseMax(0.0);
  st.slow = st.slow + dt / (g.slip_memory + dt) * (residual - st.slow);
  st.residual = residual;
  Vec6 error;
  error.head<3>() = R * origin + t - origin;
  error.tail<3>() = rotation_vector(R);
  const double a = dt / (g.velocity_filter + dt);
  st.rate = st.rate + a * ((error - st.error) / dt - st.rate);
  st.error = error;
  // The integral: frozen without a certified command or at a limit (and unwound), or
  // while a contact slips; else it moves, clamped where its wrench is at its bound.
  Frozen frozen = Frozen::moved;
  const bool slipping = st.slip.size() > 0 && st.slip.maxCoeff() > g.slip_residual;
  const double integral_force = g.max_integral_ratio * weight;
  if (!certified || at_limit) {
    frozen = certified ? Frozen::at_limit : Frozen::not_certified;
    st.integral = st.integral * (g.unwind_time / (g.unwind_time + dt));
  } else if (slipping) {
    frozen = Frozen::slips;
  } else {
    st.integral = st.integral + error * dt;
    const Vec6 w = g.ki.cwiseProduct(st.integral);
    double s_f = 1.0, s_m = 1.0;
    wrench_scales(w, integral_force, lever, s_f, s_m);
    if (s_f != 1.0 || s_m != 1.0) {
      for (int i = 0; i < 6; ++i) {
        if (w[i] != 0.0) {
          st.integral[i] *= i < 3 ? s_f : s_m;
        }
      }
    }
  }
  const Vec6 w = -(g.k.cwiseProduct(error) + g.d.cwiseProduct(st.rate) +
    bounded_wrench(g.ki.cwiseProduct(st.integral), integral_force, lever));
  st.wrench = bounded_wrench(w, g.max_force_ratio * weight, lever);
  return frozen;
}

}  // namespace

#endif  // OBJECT_LOOP_HPP_
