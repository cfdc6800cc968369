// The output fusion of output.hpp: a subsystem's record for o with its 1-sigma figures,
// the weighted vehicle solution (eq. 8, mean heading), and one epoch's records.
#include "wheelins/fusion/output.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

namespace wheelins {

namespace {
/// The first module in `use` (0 if none).
int first_used(const OutputFusion::Use& use) {
  for (int i = 0; i < kMaxModules; ++i)
    if (use[i]) return i;
  return 0;
}
}  // namespace

OutputFusion::OutputFusion(const Subsystems& subs, const FilterBackend& filter,
                           const earth::LocalFrame& frame, const NavigatorOptions& options,
                           Sink sink)
    : subs_(subs),
      filter_(filter),
      frame_(frame),
      share_level_(options.fusion.share_level),
      module_records_(options.module_records),
      offset_window_(options.fusion.heading_offset_window),
      sink_(std::move(sink)) {
  last_record_t_.fill(-1e300);
}

TrajectoryRecord OutputFusion::record(int i, bool with_lla) const {
  const Subsystem& s = subs_[i];
  const StrapdownEkf& ekf = s.ekf();
  // The sigmas to report: with the consider terms of the held states.
  const Mat21& P = filter_.reported_covariance(i);
  TrajectoryRecord r;
  r.t = ekf.state().t;
  const ReferencePointModel m = reference_point_model(s.reference_point_input());
  r.p_inN = m.r_o;
  if (with_lla) r.lla = frame_.geodetic_from_ned(r.p_inN);
  else r.lla.lat = r.lla.lon = r.lla.h = std::numeric_limits<double>::quiet_NaN();
  r.v_inN = s.reference_velocity_inW();
  const Eigen::RowVector3d J = s.heading_sensitivity();
  const double var_psi = J * P.block<3, 3>(PHI, PHI) * J.transpose();
  if (!s.is_wheel()) {
    r.rpy = subs_.body().vehicle_rpy();
    r.rpy_std.head<2>() = P.block<2, 2>(PHI, PHI).diagonal().cwiseSqrt();
  } else {
    r.rpy = Vec3(0.0, 0.0, s.vehicle_heading());
    if (subs_.has_body() && share_level_)
      r.rpy.head<2>() = subs_.body().vehicle_rpy().head<2>();
  }
  r.rpy_std.z() = std::sqrt(std::max(0.0, var_psi));
  // diag(H P H^T) over the columns eq. (7) depends on: H = [I 0 A 0 ...] over (dr, dv, phi),
  // so only the top-left 9 x 9 of P enters (the tail of H is zero, checked in debug builds).
  assert(m.H.rightCols<kStateDim - 9>().isZero());
  const Eigen::Matrix<double, 3, 9> Hs = m.H.leftCols<9>();
  r.p_std = Hs.lazyProduct(P.topLeftCorner<9, 9>()).cwiseProduct(Hs).rowwise().sum().cwiseSqrt();
  r.v_std = P.block<3, 3>(V, V).diagonal().cwiseSqrt();
  const ImuErrors& e = ekf.errors();
  r.bg = e.bg;
  r.ba = e.ba;
  r.sg = e.sg;
  r.sa = e.sa;
  r.bg_std = P.block<3, 3>(BG, BG).diagonal().cwiseSqrt();
  r.ba_std = P.block<3, 3>(BA, BA).diagonal().cwiseSqrt();
  r.sg_std = P.block<3, 3>(SG, SG).diagonal().cwiseSqrt();
  r.sa_std = P.block<3, 3>(SA, SA).diagonal().cwiseSqrt();
  return r;
}

void OutputFusion::collect(const Use& use, const Use* also, Records& recs) const {
  const int first = first_used(use);
  const int n = subs_.size();
  for (int i = 0; i < n; ++i)
    if (use[i] || i == first || (also && (*also)[i])) recs[i] = record(i, n == 1);
}

TrajectoryRecord OutputFusion::fused(const Use& use) const {
  Records recs;
  collect(use, nullptr, recs);
  return fuse(use, recs);
}

bool OutputFusion::heading_offset(int i, double& offset) const {
  if (!offset_valid_[i]) return false;
  offset = offset_[i];
  return true;
}

void OutputFusion::track_offsets(double t, const Use& vehicle, const Records& recs) {
  const int n = subs_.size();
  if (n < 2) return;
  // The offsets are to the mean of all of them that make the vehicle (not the steered wheels
  // that follow, Subsystems::follows, whose own offsets are not kept).
  for (int i = 0; i < n; ++i)
    if (vehicle[i] == subs_.follows(i)) return;
  double s = 0.0, c = 0.0;
  for (int i = 0; i < n; ++i) {
    if (!vehicle[i]) continue;
    s += subs_.weight(i) * std::sin(recs[i].rpy.z());
    c += subs_.weight(i) * std::cos(recs[i].rpy.z());
  }
  const double mean = std::atan2(s, c);
  const double a = std::clamp((t - offset_t_) / offset_window_, 0.0, 1.0);
  for (int i = 0; i < n; ++i) {
    if (!vehicle[i]) continue;
    // A new (or forgotten) offset starts from its present value.
    offset_[i] += (offset_valid_[i] ? a : 1.0) * wrap_pi(wrap_pi(recs[i].rpy.z() - mean) - offset_[i]);
    offset_valid_[i] = true;
  }
  offset_t_ = t;
}

void OutputFusion::write(double t, const Use& vehicle, const Use& in_use) {
  const int n = subs_.size();
  const bool modules_out = n > 1 && module_records_;
  collect(vehicle, modules_out ? &in_use : nullptr, recs_);
  track_offsets(t, vehicle, recs_);
  TrajectoryRecord v = fuse(vehicle, recs_);
  v.t = t;  // the epoch of the module driving the output
  sink_(0, v);
  if (modules_out)
    for (int i = 0; i < n; ++i)
      // A module whose data have stopped (not yet declared out) has nothing new.
      if (in_use[i] && subs_[i].time() > last_record_t_[i]) {
        last_record_t_[i] = subs_[i].time();
        recs_[i].lla = frame_.geodetic_from_ned(recs_[i].p_inN);
        sink_(i + 1, recs_[i]);
      }
}

TrajectoryRecord OutputFusion::fuse(const Use& use, const Records& recs) const {
  int n_use = 0;
  double ksum = 0.0;
  for (int i = 0; i < subs_.size(); ++i)
    if (use[i]) {
      ++n_use;
      ksum += subs_.weight(i);
    }
  TrajectoryRecord r = recs[first_used(use)];
  if (subs_.size() == 1 || n_use <= 1) {
    if (!std::isfinite(r.lla.lat)) r.lla = frame_.geodetic_from_ned(r.p_inN);
    return r;
  }
  // Output as in the paper: the fused reference point and the mean heading. The 1-sigma
  // of a weighted mean is bounded by the weighted mean of the sigmas whatever the
  // correlation between subsystems (Minkowski), which is what is reported.
  Vec3 p = Vec3::Zero(), v = Vec3::Zero(), p_std = Vec3::Zero(), v_std = Vec3::Zero();
  double s = 0.0, c = 0.0, psi_std = 0.0;
  int body_index = -1;
  for (int i = 0; i < subs_.size(); ++i) {
    if (!use[i]) continue;
    if (i == subs_.body_index()) body_index = i;
    const TrajectoryRecord& ri = recs[i];
    const double k = subs_.weight(i) / ksum;
    p += k * ri.p_inN;
    v += k * ri.v_inN;
    p_std += k * ri.p_std;
    v_std += k * ri.v_std;
    s += k * std::sin(ri.rpy.z());
    c += k * std::cos(ri.rpy.z());
    psi_std += k * ri.rpy_std.z();
  }
  r.p_inN = p;
  r.lla = frame_.geodetic_from_ned(p);
  r.v_inN = v;
  r.p_std = p_std;
  r.v_std = v_std;
  r.rpy.z() = std::atan2(s, c);
  r.rpy_std.z() = psi_std;
  // Known when modules that make the vehicle are missing and every one of them, and every
  // one in `use`, has an offset (a steered wheel that follows has none).
  bool known = false;
  for (int i = 0; i < subs_.size(); ++i) known = known || (!use[i] && !subs_.follows(i));
  for (int i = 0; i < subs_.size(); ++i)
    if (use[i] || !subs_.follows(i)) known = known && offset_valid_[i];
  if (known) {
    // Modules are missing: psi_i = psi_all + offset_i, so the mean of all of them is the mean
    // of these less the mean of their offsets (the heading goes on as if they were there).
    double o = 0.0;
    for (int i = 0; i < subs_.size(); ++i)
      if (use[i]) o += subs_.weight(i) / ksum * offset_[i];
    r.rpy.z() = wrap_pi(r.rpy.z() - o);
  }
  if (body_index >= 0) {
    const Vec3 rpy = subs_.body().vehicle_rpy();
    r.rpy.head<2>() = rpy.head<2>();
  }
  return r;
}

}  // namespace wheelins
