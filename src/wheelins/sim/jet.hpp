// Truncated Taylor series in time ("jets") for exact kinematics.
//
// A Jet<N> holds the Taylor coefficients c[k] = f^(k)(t0) / k! of a scalar
// function of time, k = 0..N. Arithmetic and the elementary functions below
// propagate them exactly (to rounding), so a trajectory written once as a
// composition of smooth functions yields its position, velocity, acceleration,
// attitude, angular rate and angular acceleration by the chain rule, without
// any finite differences. JVec3/JMat3 are 3-vectors / 3x3 matrices of jets.
#pragma once

#include <array>
#include <cmath>

#include "wheelins/math/rotation.hpp"

namespace wheelins::sim {

template <int N>
struct Jet {
  std::array<double, N + 1> c{};

  Jet() = default;
  /// A constant.
  Jet(double v) { c[0] = v; }  // NOLINT: implicit on purpose (constants mix with jets)
  static Jet variable(double t0) {
    Jet j(t0);
    if constexpr (N >= 1) j.c[1] = 1.0;
    return j;
  }
  double value() const { return c[0]; }
  /// k-th time derivative.
  double deriv(int k) const {
    double f = 1.0;
    for (int i = 2; i <= k; ++i) f *= i;
    return c[k] * f;
  }
  /// d/dt as a jet of the same order (the top coefficient becomes unknown: zero).
  Jet dot() const {
    Jet r;
    for (int k = 0; k < N; ++k) r.c[k] = (k + 1) * c[k + 1];
    return r;
  }

  Jet& operator+=(const Jet& o) {
    for (int k = 0; k <= N; ++k) c[k] += o.c[k];
    return *this;
  }
  Jet& operator-=(const Jet& o) {
    for (int k = 0; k <= N; ++k) c[k] -= o.c[k];
    return *this;
  }
  Jet& operator*=(double s) {
    for (double& x : c) x *= s;
    return *this;
  }
};

template <int N>
Jet<N> operator+(Jet<N> a, const Jet<N>& b) { return a += b; }
template <int N>
Jet<N> operator-(Jet<N> a, const Jet<N>& b) { return a -= b; }
template <int N>
Jet<N> operator-(Jet<N> a) { return a *= -1.0; }
template <int N>
Jet<N> operator+(Jet<N> a, double b) { a.c[0] += b; return a; }
template <int N>
Jet<N> operator+(double b, Jet<N> a) { a.c[0] += b; return a; }
template <int N>
Jet<N> operator-(Jet<N> a, double b) { a.c[0] -= b; return a; }
template <int N>
Jet<N> operator-(double b, const Jet<N>& a) { Jet<N> r = -a; r.c[0] += b; return r; }
template <int N>
Jet<N> operator*(Jet<N> a, double s) { return a *= s; }
template <int N>
Jet<N> operator*(double s, Jet<N> a) { return a *= s; }
template <int N>
Jet<N> operator/(Jet<N> a, double s) { return a *= 1.0 / s; }

template <int N>
Jet<N> operator*(const Jet<N>& a, const Jet<N>& b) {
  Jet<N> r;
  for (int k = 0; k <= N; ++k) {
    double s = 0.0;
    for (int j = 0; j <= k; ++j) s += a.c[j] * b.c[k - j];
    r.c[k] = s;
  }
  return r;
}

template <int N>
Jet<N> operator/(const Jet<N>& a, const Jet<N>& b) {
  Jet<N> r;
  for (int k = 0; k <= N; ++k) {
    double s = a.c[k];
    for (int j = 1; j <= k; ++j) s -= b.c[j] * r.c[k - j];
    r.c[k] = s / b.c[0];
  }
  return r;
}

/// f(u) where f' = g(u): f_k = (1/k) sum_{j=1..k} j u_j g_{k-j}, with g given as a jet
/// (only its coefficients 0..N-1 are used).
template <int N>
Jet<N> integrate_chain(double f0, const Jet<N>& u, const Jet<N>& g) {
  Jet<N> r(f0);
  for (int k = 1; k <= N; ++k) {
    double s = 0.0;
    for (int j = 1; j <= k; ++j) s += j * u.c[j] * g.c[k - j];
    r.c[k] = s / k;
  }
  return r;
}

template <int N>
void sincos(const Jet<N>& u, Jet<N>& s, Jet<N>& co) {
  s = Jet<N>(std::sin(u.c[0]));
  co = Jet<N>(std::cos(u.c[0]));
  for (int k = 1; k <= N; ++k) {
    double ss = 0.0, cc = 0.0;
    for (int j = 1; j <= k; ++j) {
      ss += j * u.c[j] * co.c[k - j];
      cc -= j * u.c[j] * s.c[k - j];
    }
    s.c[k] = ss / k;
    co.c[k] = cc / k;
  }
}
template <int N>
Jet<N> sin(const Jet<N>& u) { Jet<N> s, c; sincos(u, s, c); return s; }
template <int N>
Jet<N> cos(const Jet<N>& u) { Jet<N> s, c; sincos(u, s, c); return c; }

template <int N>
Jet<N> exp(const Jet<N>& u) {
  Jet<N> e(std::exp(u.c[0]));
  for (int k = 1; k <= N; ++k) {
    double s = 0.0;
    for (int j = 1; j <= k; ++j) s += j * u.c[j] * e.c[k - j];
    e.c[k] = s / k;
  }
  return e;
}

template <int N>
Jet<N> sqrt(const Jet<N>& u) {
  Jet<N> r(std::sqrt(u.c[0]));
  for (int k = 1; k <= N; ++k) {
    double s = u.c[k];
    for (int j = 1; j < k; ++j) s -= r.c[j] * r.c[k - j];
    r.c[k] = s / (2.0 * r.c[0]);
  }
  return r;
}

template <int N>
Jet<N> atan(const Jet<N>& u) {
  const Jet<N> g = Jet<N>(1.0) / (1.0 + u * u);
  return integrate_chain(std::atan(u.c[0]), u, g);
}

/// atan2(y, x) with the value taken from std::atan2 plus `branch` (for unwrapping).
template <int N>
Jet<N> atan2(const Jet<N>& y, const Jet<N>& x, double branch = 0.0) {
  // d/dt atan2 = (x y' - y x') / (x^2 + y^2): build the derivative as a jet, integrate.
  const Jet<N> d = (x * y.dot() - y * x.dot()) / (x * x + y * y);
  Jet<N> r(std::atan2(y.c[0], x.c[0]) + branch);
  for (int k = 1; k <= N; ++k) r.c[k] = d.c[k - 1] / k;
  return r;
}

template <int N>
struct JVec3 {
  std::array<Jet<N>, 3> v;
  JVec3() = default;
  JVec3(const Jet<N>& x, const Jet<N>& y, const Jet<N>& z) : v{x, y, z} {}
  explicit JVec3(const Vec3& c) : v{Jet<N>(c.x()), Jet<N>(c.y()), Jet<N>(c.z())} {}
  Jet<N>& operator[](int i) { return v[i]; }
  const Jet<N>& operator[](int i) const { return v[i]; }
  /// The k-th time derivative as a plain vector.
  Vec3 deriv(int k) const { return {v[0].deriv(k), v[1].deriv(k), v[2].deriv(k)}; }
  Vec3 value() const { return deriv(0); }
  JVec3 operator+(const JVec3& o) const { return {v[0] + o.v[0], v[1] + o.v[1], v[2] + o.v[2]}; }
  JVec3 operator-(const JVec3& o) const { return {v[0] - o.v[0], v[1] - o.v[1], v[2] - o.v[2]}; }
  JVec3 operator*(const Jet<N>& s) const { return {v[0] * s, v[1] * s, v[2] * s}; }
  JVec3 operator*(double s) const { return {v[0] * s, v[1] * s, v[2] * s}; }
  /// Time derivative (top coefficient lost, as Jet::dot).
  JVec3 dot() const { return {v[0].dot(), v[1].dot(), v[2].dot()}; }
};

template <int N>
Jet<N> dot(const JVec3<N>& a, const JVec3<N>& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
template <int N>
JVec3<N> cross(const JVec3<N>& a, const JVec3<N>& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

/// 3x3 matrix of jets, row-major m[r][c].
template <int N>
struct JMat3 {
  std::array<std::array<Jet<N>, 3>, 3> m;
  JMat3() = default;
  explicit JMat3(const Mat3& c) {
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k) m[r][k] = Jet<N>(c(r, k));
  }
  static JMat3 from_columns(const JVec3<N>& a, const JVec3<N>& b, const JVec3<N>& c) {
    JMat3 r;
    for (int i = 0; i < 3; ++i) {
      r.m[i][0] = a[i];
      r.m[i][1] = b[i];
      r.m[i][2] = c[i];
    }
    return r;
  }
  Mat3 deriv(int k) const {
    Mat3 r;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) r(i, j) = m[i][j].deriv(k);
    return r;
  }
  Mat3 value() const { return deriv(0); }
  JVec3<N> col(int c) const { return {m[0][c], m[1][c], m[2][c]}; }
  JMat3 operator*(const JMat3& o) const {
    JMat3 r;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) r.m[i][j] = m[i][0] * o.m[0][j] + m[i][1] * o.m[1][j] + m[i][2] * o.m[2][j];
    return r;
  }
  JMat3 operator*(const Mat3& o) const {
    JMat3 r;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) r.m[i][j] = m[i][0] * o(0, j) + m[i][1] * o(1, j) + m[i][2] * o(2, j);
    return r;
  }
  JVec3<N> operator*(const JVec3<N>& x) const {
    JVec3<N> r;
    for (int i = 0; i < 3; ++i) r[i] = m[i][0] * x[0] + m[i][1] * x[1] + m[i][2] * x[2];
    return r;
  }
  JVec3<N> operator*(const Vec3& x) const {
    JVec3<N> r;
    for (int i = 0; i < 3; ++i) r[i] = m[i][0] * x[0] + m[i][1] * x[1] + m[i][2] * x[2];
    return r;
  }
};

template <int N>
JMat3<N> operator*(const Mat3& a, const JMat3<N>& b) {
  JMat3<N> r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.m[i][j] = a(i, 0) * b.m[0][j] + a(i, 1) * b.m[1][j] + a(i, 2) * b.m[2][j];
  return r;
}

/// Elementary rotations with a jet angle (same convention as wheelins::rot_x etc.).
template <int N>
JMat3<N> jrot_x(const Jet<N>& a) {
  Jet<N> s, c;
  sincos(a, s, c);
  JMat3<N> r(Mat3::Identity());
  r.m[1][1] = c; r.m[1][2] = -s;
  r.m[2][1] = s; r.m[2][2] = c;
  return r;
}
template <int N>
JMat3<N> jrot_y(const Jet<N>& a) {
  Jet<N> s, c;
  sincos(a, s, c);
  JMat3<N> r(Mat3::Identity());
  r.m[0][0] = c; r.m[0][2] = s;
  r.m[2][0] = -s; r.m[2][2] = c;
  return r;
}
template <int N>
JMat3<N> jrot_z(const Jet<N>& a) {
  Jet<N> s, c;
  sincos(a, s, c);
  JMat3<N> r(Mat3::Identity());
  r.m[0][0] = c; r.m[0][1] = -s;
  r.m[1][0] = s; r.m[1][1] = c;
  return r;
}
/// ZYX Euler angles to a DCM (wheelins::dcm_from_euler with jets).
template <int N>
JMat3<N> jdcm_from_euler(const Jet<N>& roll, const Jet<N>& pitch, const Jet<N>& yaw) {
  return jrot_z(yaw) * jrot_y(pitch) * jrot_x(roll);
}

/// For a rotation C(t) = C_b^a, the angular rate of b w.r.t. a in the b-frame:
/// skew(w) = C^T dC/dt.
inline Vec3 vee(const Mat3& S) { return 0.5 * Vec3(S(2, 1) - S(1, 2), S(0, 2) - S(2, 0), S(1, 0) - S(0, 1)); }
template <int N>
Vec3 body_rate(const JMat3<N>& C) {
  return vee(C.value().transpose() * C.deriv(1));
}
/// d/dt of body_rate: (C^T C')' = C'^T C' + C^T C''  (the first term is symmetric, so drops
/// out of vee).
template <int N>
Vec3 body_rate_dot(const JMat3<N>& C) {
  return vee(C.value().transpose() * C.deriv(2));
}

}  // namespace wheelins::sim
