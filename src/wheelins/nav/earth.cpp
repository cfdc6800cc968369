#include "wheelins/nav/earth.hpp"

#include <cmath>

namespace wheelins::earth {

double normal_gravity(double lat, double h) {
  // Somigliana formula with the usual free-air height correction.
  const double s2 = std::sin(lat) * std::sin(lat);
  const double g0 = 9.7803253359 * (1.0 + 0.00193185265241 * s2) / std::sqrt(1.0 - kE2 * s2);
  return g0 - 3.086e-6 * h;
}

Vec3 earth_rate_ned(double lat) { return kOmegaIE * Vec3(std::cos(lat), 0.0, -std::sin(lat)); }

Vec3 ecef_from_geodetic(const Geodetic& g) {
  const double sl = std::sin(g.lat), cl = std::cos(g.lat);
  const double n = kA / std::sqrt(1.0 - kE2 * sl * sl);
  return {(n + g.h) * cl * std::cos(g.lon), (n + g.h) * cl * std::sin(g.lon),
          (n * (1.0 - kE2) + g.h) * sl};
}

Geodetic geodetic_from_ecef(const Vec3& r) {
  const double p = std::hypot(r.x(), r.y());
  Geodetic g;
  g.lon = std::atan2(r.y(), r.x());
  double lat = std::atan2(r.z(), p * (1.0 - kE2));
  double h = 0.0;
  for (int i = 0; i < 8; ++i) {  // converges to sub-micrometre in a few steps
    const double sl = std::sin(lat);
    const double n = kA / std::sqrt(1.0 - kE2 * sl * sl);
    h = p / std::cos(lat) - n;
    lat = std::atan2(r.z(), p * (1.0 - kE2 * n / (n + h)));
  }
  g.lat = lat;
  g.h = h;
  return g;
}

Mat3 dcm_ecef_to_ned(double lat, double lon) {
  const double sl = std::sin(lat), cl = std::cos(lat), so = std::sin(lon), co = std::cos(lon);
  Mat3 C;
  C << -sl * co, -sl * so, cl, -so, co, 0.0, -cl * co, -cl * so, -sl;
  return C;
}

LocalFrame::LocalFrame(const Geodetic& origin)
    : origin_(origin),
      origin_ecef_(ecef_from_geodetic(origin)),
      C_EtoN_(dcm_ecef_to_ned(origin.lat, origin.lon)) {}

Vec3 LocalFrame::ned_from_geodetic(const Geodetic& g) const {
  return C_EtoN_ * (ecef_from_geodetic(g) - origin_ecef_);
}

Geodetic LocalFrame::geodetic_from_ned(const Vec3& ned) const {
  return geodetic_from_ecef(origin_ecef_ + C_EtoN_.transpose() * ned);
}

}  // namespace wheelins::earth
