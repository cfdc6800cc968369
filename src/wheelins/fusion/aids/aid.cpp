// The shared queries of aid.hpp.
#include "wheelins/fusion/aids/aid.hpp"

namespace wheelins {

void AidContext::share_level() const {
  if (!level_shared()) return;
  const Vec3 rpy = subs.body().vehicle_rpy();
  for (int i = 0; i < subs.size(); ++i)
    if (subs.is_wheel(i)) subs.wheel(i).set_vehicle_level(rpy.x(), rpy.y());
}

void AidContext::act_on_faults() const {
  if (!faults.actions_pending()) return;
  const FaultActions a = faults.take_actions();
  for (int i = 0; i < subs.size(); ++i)
    if (a.forget_heading_offset[static_cast<std::size_t>(i)]) output.forget_heading_offset(i);
  if (a.restart) {
    const FaultActions::Restart& r = *a.restart;
    if (r.revert_errors) subs[r.module].ekf().set_errors(r.errors);
    subs[r.module].restart(r.f_now, r.fix);
    filter.restarted(r.module);
  }
}

}  // namespace wheelins
