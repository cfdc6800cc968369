// The earth model of earth.hpp: normal gravity, earth rate, and geodetic <-> local NED.
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
  // Bowring's closed form (parametric latitude as the start), then one step of the
  // fixed-point latitude iteration: below 1e-13 rad and 1e-6 m for heights within
  // +-100 km (Earth.GeodeticFromEcefInvertsEcefFromGeodetic in tests/test_rotation.cpp).
  const double b = kA * std::sqrt(1.0 - kE2);
  const double ep2 = kE2 / (1.0 - kE2);  // second eccentricity squared
  const double p = std::hypot(r.x(), r.y());
  Geodetic g;
  g.lon = std::atan2(r.y(), r.x());
  const double beta = std::atan2(r.z() * kA, p * b);
  const double sb = std::sin(beta), cb = std::cos(beta);
  double lat = std::atan2(r.z() + ep2 * b * sb * sb * sb, p - kE2 * kA * cb * cb * cb);
  double sl = std::sin(lat);
  double n = kA / std::sqrt(1.0 - kE2 * sl * sl);
  lat = std::atan2(r.z() + kE2 * n * sl, p);
  sl = std::sin(lat);
  const double cl = std::cos(lat);
  n = kA / std::sqrt(1.0 - kE2 * sl * sl);
  g.lat = lat;
  // Well conditioned at every latitude (no division by cos(lat)).
  g.h = p * cl + r.z() * sl - n * (1.0 - kE2 * sl * sl);
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
