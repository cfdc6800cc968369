// The distributed back-end of filter_backend.hpp (one EKF per subsystem), and the factory
// that picks it or the centralized one.
#include "wheelins/fusion/filter_backend.hpp"

#include "wheelins/fusion/centralized.hpp"

namespace wheelins {

namespace {

/// The paper's filter: one EKF per subsystem, each owning its covariance.
class DistributedFilter final : public FilterBackend {
 public:
  explicit DistributedFilter(Subsystems& subs) : subs_(subs) {}
  bool joint() const override { return false; }
  void start() override {}
  void propagated(int i) override {
    StrapdownEkf& ekf = subs_[i].ekf();
    if (ekf.covariance_due()) ekf.flush_covariance();
  }
  void flush() override {
    for (int i = 0; i < subs_.size(); ++i) subs_[i].ekf().flush_covariance();
  }
  const Mat21& covariance(int i, Mat21&) const override { return subs_[i].ekf().covariance(); }
  const Mat21& reported_covariance(int i) const override {
    return subs_[i].ekf().reported_covariance();
  }
  UpdateReport fuse(const Measurement& m) override {
    // A velocity update leaves the subsystem's consider states (velocity_gain) alone.
    const ProcessNoise& q = subs_[m.module].process_noise();
    const bool mask = m.velocity && q.velocity_consider();
    return subs_[m.module].ekf().update<3>(m.H_own, m.dz, m.R, m.gate,
                                           mask ? &q.velocity_gain : nullptr);
  }
  void restarted(int) override {}

 private:
  Subsystems& subs_;
};

}  // namespace

std::unique_ptr<FilterBackend> make_filter_backend(Subsystems& subs, bool centralized) {
  if (centralized && subs.size() > 1) return std::make_unique<CentralizedFilter>(subs);
  return std::make_unique<DistributedFilter>(subs);
}

}  // namespace wheelins
