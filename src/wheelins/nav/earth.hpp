// Earth model: WGS-84 constants, normal gravity, and the conversion between
// geodetic coordinates and the local north-east-down tangent frame at an origin.
//
// wheelins navigates in a flat local-level w-frame (paper Table 2): constant
// gravity along +z (down) and, optionally, the earth rotation rate expressed in
// that frame. Truth files hold latitude/longitude/height; they are mapped into
// the tangent frame through ECEF, exactly in both directions.
#pragma once

#include "wheelins/math/rotation.hpp"

namespace wheelins::earth {

constexpr double kA = 6378137.0;                 // WGS-84 semi-major axis [m]
constexpr double kF = 1.0 / 298.257223563;       // flattening
constexpr double kE2 = kF * (2.0 - kF);          // first eccentricity squared
constexpr double kOmegaIE = 7.2921151467e-5;     // earth rotation rate [rad/s]

/// Geodetic position: latitude and longitude in radians, ellipsoidal height in metres.
struct Geodetic {
  double lat = 0.0;
  double lon = 0.0;
  double h = 0.0;
};

/// Somigliana normal gravity magnitude [m/s^2] at latitude lat [rad], height h [m].
double normal_gravity(double lat, double h);

/// Earth rotation rate in the NED frame at latitude lat: Omega*[cos lat, 0, -sin lat].
Vec3 earth_rate_ned(double lat);

Vec3 ecef_from_geodetic(const Geodetic& g);
Geodetic geodetic_from_ecef(const Vec3& r_ecef);
/// C_e^n: rotates ECEF vectors into the NED frame at (lat, lon).
Mat3 dcm_ecef_to_ned(double lat, double lon);

/// The local tangent (NED) frame at a fixed origin.
class LocalFrame {
 public:
  LocalFrame() = default;
  explicit LocalFrame(const Geodetic& origin);
  const Geodetic& origin() const { return origin_; }
  /// North/east/down metres of a geodetic point.
  Vec3 ned_from_geodetic(const Geodetic& g) const;
  Geodetic geodetic_from_ned(const Vec3& ned) const;

 private:
  Geodetic origin_{};
  Vec3 origin_ecef_ = ecef_from_geodetic(Geodetic{});
  Mat3 C_EtoN_ = dcm_ecef_to_ned(0.0, 0.0);
};

}  // namespace wheelins::earth
