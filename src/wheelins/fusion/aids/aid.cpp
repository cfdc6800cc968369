// The shared queries of aid.hpp.
#include "wheelins/fusion/aids/aid.hpp"

namespace wheelins {

void AidContext::share_level() const {
  if (!level_shared()) return;
  const Vec3 rpy = subs.body().vehicle_rpy();
  for (int i = 0; i < subs.size(); ++i)
    if (subs.is_wheel(i)) subs.wheel(i).set_vehicle_level(rpy.x(), rpy.y());
}

}  // namespace wheelins
