// Copyright 2026 grasp_torque_opt developers
//
// Use of this source code is governed by a BSD-style
// license that can be found in the LICENSE file or at
// https://developers.google.com/open-source/licenses/bsd
//
// SPDX-License-Identifier: BSD-3-Clause

// The kinematics of a tree of 1-DoF revolute and prismatic joints on a fixed root
// (core/tree_kinematics.TreeKinematics, whose numpy twin this is): the frame placements
// and LOCAL_WORLD_ALIGNED Jacobians Pinocchio's getFrameJacobian gives, for the batch
// scorer's N configurations (kinematics_batch) and for the node's cycle
// (FastCycle::solve_q), which would otherwise cross into Pinocchio's Python binding
// twice a contact. Pinocchio's C++ cannot be handed the Python binding's model, so
// the model's tables are copied in, and TreeKinematics.check holds the result to
// Pinocchio's before either path uses it. Included by fast_cycle.hpp.

#ifndef TREE_KINEMATICS_HPP_
#define TREE_KINEMATICS_HPP_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/SVD>

#include <cstdint>
#include <stdexcept>
#include <utility>
#include <vector>

namespace
{

class Tree
{
public:
  using M3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
  using V3 = Eigen::Vector3d;

  // Joint j (1..nj-1) has parent parents[j] (< j), is revolute (kinds[j] = 0) or
  // prismatic (1) along axes[j] (joint frame), is placed at (Rp[j], tp[j]) in its
  // parent, and has position q[idx_q[j]] and velocity column idx_v[j]; joint 0 is the
  // root. Throws std::invalid_argument where a table does not fit.
  Tree(
    int64_t nj, const int64_t * parents, const int64_t * kinds, const double * axes,
    const double * Rp, const double * tp, const int64_t * idx_q, const int64_t * idx_v,
    int64_t nq, int64_t nv)
  : nq_(nq), nv_(nv), parent_(parents, parents + nj), kind_(kinds, kinds + nj),
    iq_(idx_q, idx_q + nj), iv_(idx_v, idx_v + nj), a_(nj), tp_(nj), Rp_(nj),
    support_(nj), R_(nj), t_(nj), axis_(nj)
  {
    if (nj < 1 || nv < 1) {
      throw std::invalid_argument("joint or frame tables of the wrong shape");
    }
    for (int64_t j = 0; j < nj; ++j) {
      a_[j] = Eigen::Map<const V3>(axes + 3 * j);
      tp_[j] = Eigen::Map<const V3>(tp + 3 * j);
      Rp_[j] = Eigen::Map<const M3>(Rp + 9 * j);
      if (j == 0) {
        continue;
      }
      if (parent_[j] < 0 || parent_[j] >= j || iq_[j] < 0 || iq_[j] >= nq ||
        iv_[j] < 0 || iv_[j] >= nv)
      {
        throw std::invalid_argument("joint table out of range");
      }
      support_[j] = support_[parent_[j]];
      support_[j].push_back(j);
    }
  }

  int64_t nq() const {return nq_;}
  int64_t nv() const {return nv_;}
  int64_t joints() const {return static_cast<int64_t>(parent_.size());}

  // Every joint's world placement at configuration q (nq values).
  void place(const double * q)
  {
    R_[0].setIdentity();
    t_[0].setZero();
    for (size_t j = 1; j < parent_.size(); ++j) {
      const int64_t up = parent_[j];
      const M3 base = R_[up] * Rp_[j];
      t_[j] = t_[up] + R_[up] * tp_[j];
      if (kind_[j] == 0) {
        R_[j] = base * Eigen::AngleAxisd(q[iq_[j]], a_[j]).toRotationMatrix();
      } else {
        R_[j] = base;
        t_[j] += q[iq_[j]] * (base * a_[j]);
      }
      axis_[j] = R_[j] * a_[j];
    }
  }

  // The world placement (R, o) of the frame placed at (Rf, tf) in joint j, at the
  // configuration of the last place().
  void placement(int64_t j, const double * Rf, const double * tf, M3 & R, V3 & o) const
  {
    R = R_[j] * Eigen::Map<const M3>(Rf);
    o = t_[j] + R_[j] * Eigen::Map<const V3>(tf);
  }

  // The placement (4 x 4, row-major, into oMf) and the LOCAL_WORLD_ALIGNED Jacobian
  // (6 x nv, row-major, into J6, every entry written) of the frame placed at (Rf, tf) in
  // joint j, at the configuration of the last place().
  void frame(int64_t j, const double * Rf, const double * tf, double * oMf, double * J6) const
  {
    M3 Rw;
    V3 o;
    placement(j, Rf, tf, Rw, o);
    Eigen::Map<Eigen::Matrix<double, 4, 4, Eigen::RowMajor>> M(oMf);
    M.setZero();
    M.topLeftCorner<3, 3>() = Rw;
    M.topRightCorner<3, 1>() = o;
    M(3, 3) = 1.0;
    Eigen::Map<Eigen::Matrix<double, 6, Eigen::Dynamic, Eigen::RowMajor>> Jm(J6, 6, nv_);
    Jm.setZero();
    for (int64_t s : support_[j]) {
      if (kind_[s] == 0) {
        Jm.block<3, 1>(0, iv_[s]) = axis_[s].cross(o - t_[s]);
        Jm.block<3, 1>(3, iv_[s]) = axis_[s];
      } else {
        Jm.block<3, 1>(0, iv_[s]) = axis_[s];
      }
    }
  }

private:
  int64_t nq_, nv_;
  std::vector<int64_t> parent_, kind_, iq_, iv_;
  std::vector<V3> a_, tp_;
  std::vector<M3> Rp_;
  std::vector<std::vector<int64_t>> support_;
  std::vector<M3> R_;
  std::vector<V3> t_, axis_;
};

// Material points of a tree's links in the base frame, and the rigid motion that best
// carries reference points to them (core/object_from_hand.ObjectFromHand's points and
// estimate, whose numpy twin this is): point i is local[i] in the frame placed at
// (Rf[i], tf[i]) in joint fparent[i]; with a base frame (base >= 0, placed at (Rb, tb)
// in joint base) the points are in its axes about its origin, else in the root's.
class TreePoints
{
public:
  using M3 = Tree::M3;
  using V3 = Tree::V3;
  using Points = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

  TreePoints(
    Tree tree, int64_t p, const int64_t * fparent, const double * Rf, const double * tf,
    const double * local, int64_t base, const double * Rb, const double * tb)
  : tree_(std::move(tree)), fparent_(fparent, fparent + p), Rf_(Rf, Rf + 9 * p),
    tf_(tf, tf + 3 * p), local_(Eigen::Map<const Points>(local, p, 3)), base_(base),
    Rb_(Rb, Rb + 9), tb_(tb, tb + 3)
  {
    for (int64_t j : fparent_) {
      if (j < 0 || j >= tree_.joints()) {
        throw std::invalid_argument("frame table out of range");
      }
    }
    if (base_ >= tree_.joints()) {
      throw std::invalid_argument("frame table out of range");
    }
  }

  int64_t size() const {return static_cast<int64_t>(fparent_.size());}
  int64_t nq() const {return tree_.nq();}

  // The points at configuration q (nq values), (p, 3) into out.
  void points(const double * q, Points & out)
  {
    tree_.place(q);
    const int64_t p = size();
    out.resize(p, 3);
    M3 R;
    V3 o;
    for (int64_t i = 0; i < p; ++i) {
      tree_.placement(fparent_[i], Rf_.data() + 9 * i, tf_.data() + 3 * i, R, o);
      out.row(i) = (R * local_.row(i).transpose() + o).transpose();
    }
    if (base_ >= 0) {
      tree_.placement(base_, Rb_.data(), tb_.data(), R, o);
      for (int64_t i = 0; i < p; ++i) {
        out.row(i) = ((out.row(i).transpose() - o).transpose() * R);
      }
    }
  }

  // Kabsch's rotation R minimising sum |p_i - m - R (p0_i - m0)|^2 (identity with fewer
  // than three points), t = m - R m0, and each point's distance from the motion.
  static void fit(const Points & p0, const Points & p, M3 & R, V3 & t, Eigen::VectorXd & residuals)
  {
    const V3 m0 = p0.colwise().mean().transpose(), m = p.colwise().mean().transpose();
    R.setIdentity();
    if (p.rows() >= 3) {
      const Eigen::Matrix3d B = (p.rowwise() - m.transpose()).transpose() *
        (p0.rowwise() - m0.transpose());
      Eigen::JacobiSVD<Eigen::Matrix3d> svd(B, Eigen::ComputeFullU | Eigen::ComputeFullV);
      Eigen::Matrix3d U = svd.matrixU();
      const Eigen::Matrix3d V = svd.matrixV();
      if ((U * V.transpose()).determinant() < 0.0) {
        U.col(2) = -U.col(2);
      }
      R = U * V.transpose();
    }
    t = m - R * m0;
    residuals = ((p0 * R.transpose()).rowwise() + t.transpose() - p).rowwise().norm();
  }

private:
  Tree tree_;
  std::vector<int64_t> fparent_;
  std::vector<double> Rf_, tf_;
  Points local_;
  int64_t base_;
  std::vector<double> Rb_, tb_;
};

}  // namespace

#endif  // TREE_KINEMATICS_HPP_
