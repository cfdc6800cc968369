// Rigid fits of one point set onto another (the trajectory's positions at the truth epochs onto
// the truth's), for the whole-trajectory alignment of `wheelins evaluate --align` and for the
// frame check that tells a mirrored trajectory (an ENU file read as NED) from a drifted one.
//
// Fit (Umeyama 1991, without scale): the rotation R and translation t minimising
//   sum_i |b_i - (R a_i + t)|^2,
// with the centred sets A, B and M = sum_i (b_i - mean b)(a_i - mean a)^T:
//   * SE(3): M = U D V^T, R = U diag(1, 1, det(U V^T)) V^T (a proper rotation);
//   * SE(2) (rotation about the vertical only, 3-D translation): R = Rz(theta) with
//     theta = atan2(M10 - M01, M00 + M11);
//   t = mean b - R mean a. rms = sqrt(residual sum / n).
// Mirror check (horizontal, north-east only): the least-squares residual of the best proper
// rotation against that of the best reflection, both with a free translation. With N the
// centred 2x2 sum of a_i b_i^T, the best proper rotation leaves
//   |A|^2 + |B|^2 - 2 sqrt((N00 + N11)^2 + (N01 - N10)^2)
// and the best reflection the same with sqrt((N00 - N11)^2 + (N01 + N10)^2).
#pragma once

#include <vector>

#include "wheelins/nav/types.hpp"

namespace wheelins::eval {

/// The whole-trajectory alignments of `wheelins evaluate` (named as evo names them).
enum class AlignFit {
  kNone,
  kSe3,  ///< --align: rotation and translation in 3-D (evo_ape --align)
  kSe2,  ///< --align-se2: rotation about the vertical and translation in 3-D
};

struct RigidFit {
  bool found = false;  ///< at least 3 points (SE(2): 2)
  Mat3 R = Mat3::Identity();
  Vec3 t = Vec3::Zero();
  double rms = 0.0;       ///< [m] after the fit
  std::size_t points = 0;
};

/// b ~ R a + t over the pairs (a_i, b_i) (see the header).
RigidFit fit_rigid(const std::vector<Vec3>& a, const std::vector<Vec3>& b, AlignFit kind);

struct MirrorCheck {
  std::size_t points = 0;
  double rotation_rms = 0.0;    ///< [m] horizontal rms after the best rotation + shift
  double reflection_rms = 0.0;  ///< [m] horizontal rms after the best reflection + shift
  /// The trajectory is the mirror image of the truth: a reflection fits it far better than any
  /// rotation (reflection_rms < rotation_rms / 4 and rotation_rms - reflection_rms > 2 m, over
  /// at least 10 points). A track without turns fits both alike and is never called mirrored.
  bool mirrored = false;
};

/// The horizontal (north-east) shape of a against b.
MirrorCheck check_mirror(const std::vector<Vec3>& a, const std::vector<Vec3>& b);

}  // namespace wheelins::eval
