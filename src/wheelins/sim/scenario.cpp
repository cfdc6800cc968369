// The scenarios of scenario.hpp: the default loop, paths from KML/CSV with a speed
// profile, terrain, skid, and the exact vehicle motion they give.
#include "wheelins/sim/scenario.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "wheelins/io/binary.hpp"
#include "wheelins/io/text_util.hpp"
#include "wheelins/nav/types.hpp"

namespace wheelins::sim {
namespace {

/// f(u(t)) as a jet from the derivatives f^(k)(u0), k = 0..kOrder (exact Taylor composition).
J compose(const double* f, const J& u) {
  J d = u;
  d.c[0] = 0.0;
  J r(f[0]);
  J pw(1.0);
  double fact = 1.0;
  for (int k = 1; k <= kOrder; ++k) {
    pw = pw * d;
    fact *= k;
    r += pw * (f[k] / fact);
  }
  return r;
}

/// Component `dim` of the path's `first`-th derivative with respect to u, as a jet in t: the
/// path's u-derivatives `pd` at u(t) composed with the jet u(t).
J path_derivative(const std::array<double, 2>* pd, int first, int dim, const J& u) {
  double f[kOrder + 1];
  for (int k = 0; k <= kOrder; ++k) f[k] = pd[first + k][dim];
  return compose(f, u);
}

/// The signed curvature of a horizontal curve (north, east) from its first and second
/// derivatives with respect to any parameter: positive turning right (clockwise seen from above).
J horizontal_curvature(const J& xn, const J& xe, const J& xnn, const J& xee) {
  const J m2 = xn * xn + xe * xe;
  const J m = sqrt(m2);
  return (xn * xee - xe * xnn) / (m2 * m);
}

// 4-point Gauss-Legendre on [-1, 1].
constexpr double kGlX[4] = {-0.86113631159405257522, -0.33998104358485626480,
                            0.33998104358485626480, 0.86113631159405257522};
constexpr double kGlW[4] = {0.34785484513745385737, 0.65214515486254614263,
                            0.65214515486254614263, 0.34785484513745385737};

std::string quote(const std::filesystem::path& p) { return "'" + p.string() + "'"; }

/// The smoothed path of a polyline as PathScenario drives it: knots at the cumulative chord
/// lengths (vertices closer than 1e-6 m to the last kept one dropped), extended beyond its ends
/// along its first and last chords. Empty knots if the polyline has no length.
GaussPolyline<2> smoothed_path(const std::vector<std::array<double, 2>>& pts, double sigma) {
  std::vector<double> u{0.0};
  std::vector<std::array<double, 2>> p{pts[0]};
  for (std::size_t i = 1; i < pts.size(); ++i) {
    const double d = std::hypot(pts[i][0] - p.back()[0], pts[i][1] - p.back()[1]);
    if (d < 1e-6) continue;
    u.push_back(u.back() + d);
    p.push_back(pts[i]);
  }
  if (u.size() < 2) return {};
  const std::size_t n = u.size();
  std::array<double, 2> t0{(p[1][0] - p[0][0]) / (u[1] - u[0]), (p[1][1] - p[0][1]) / (u[1] - u[0])};
  std::array<double, 2> t1{(p[n - 1][0] - p[n - 2][0]) / (u[n - 1] - u[n - 2]),
                           (p[n - 1][1] - p[n - 2][1]) / (u[n - 1] - u[n - 2])};
  return GaussPolyline<2>(u, p, sigma, t0, t1);
}

/// The curvature of a smoothed path at u (positive turning right).
double smoothed_curvature(const GaussPolyline<2>& path, double u) {
  std::array<double, 2> d[3];
  path.eval(u, 2, d);
  const double m = std::hypot(d[1][0], d[1][1]);
  return (d[1][0] * d[2][1] - d[1][1] * d[2][0]) / (m * m * m);
}

/// The arc before the T of a start with the wheels turned (DefaultScenarioOptions::
/// start_curvature): vertices on a circle that ends at pts[0] heading along pts[0] -> pts[1].
/// The vehicle starts `lead` (chord length) before pts[0]; the circle goes on backwards for 12
/// path sigmas, so the smoothing sees an arc behind the start (the polyline's straight
/// extension would halve the curvature there). The Gaussian smoothing of a circle of radius R
/// along its length is a circle of radius R exp(-sigma^2 / 2R^2), and the T ahead pulls the
/// curvature down: the circle's curvature is solved (secant method) so that the smoothed path's
/// curvature at the start is the target.
struct StartArc {
  std::vector<std::array<double, 2>> vertices;  ///< before pts[0] (pts[0] not included)
  std::size_t start = 0;                        ///< the vertex where o starts
  double lead = 0.0;                            ///< chord length from the start to pts[0] [m]
  double curvature = 0.0;                       ///< of the circle [1/m]
};

StartArc start_arc(const std::vector<std::array<double, 2>>& pts, double kappa, double sigma) {
  const double dn = pts[1][0] - pts[0][0], de = pts[1][1] - pts[0][1];
  const double psi1 = std::atan2(de, dn);
  const double back = 12.0 * sigma;
  // The arc (polyline length): a quarter turn, at most max(20 m, 3 sigma), but at least 5 m of
  // driving + 2 sigma (the smoothing straightens the path over ~2 sigma before the T). The
  // smoothed circle is smaller by about k / kappa, and so is the distance driven along it.
  // Vertices at most sigma / 2 and 30 degrees apart: the smoothing leaves of the chords' ripple
  // (period h) exp(-2 pi^2 sigma^2 / h^2) = 5e-35; their mean radius is solved below.
  auto arc_length = [&](double k) {
    return std::max(5.0 * std::abs(kappa / k) + 2.0 * sigma,
                    std::min(0.5 * kPi / std::abs(k), std::max(20.0, 3.0 * sigma)));
  };
  const double h0 = std::min(0.5 * sigma, 30.0 * kDeg / std::abs(kappa));
  const int n_arc = std::max(4, static_cast<int>(std::ceil(arc_length(kappa) / h0)));
  const int n_back = static_cast<int>(std::ceil(back / h0));
  auto build = [&](double k) {
    StartArc a;
    a.curvature = k;
    const double la = arc_length(k), h = la / n_arc;
    // Arc length s <= 0 from pts[0]: heading psi1 + k s.
    for (int i = -(n_arc + n_back); i < 0; ++i) {
      const double s = i * h, psi = psi1 + k * s;
      a.vertices.push_back({pts[0][0] + (std::sin(psi) - std::sin(psi1)) / k,
                            pts[0][1] + (std::cos(psi1) - std::cos(psi)) / k});
    }
    a.start = static_cast<std::size_t>(n_back);
    a.lead = n_arc * 2.0 * std::sin(0.5 * std::abs(k) * h) / std::abs(k);
    return a;
  };
  // The curvature of the smoothed path (the arc and the first sides of the T) at the start.
  auto smoothed = [&](const StartArc& a) {
    std::vector<std::array<double, 2>> all = a.vertices;
    for (std::size_t i = 0; i < pts.size() && i < 16; ++i) all.push_back(pts[i]);
    const GaussPolyline<2> path = smoothed_path(all, sigma);
    return smoothed_curvature(path, path.knots()[a.start]);
  };
  // Secant on log |k|: the smoothed curvature grows with the circle's (it is not a contraction,
  // so a fixed-point iteration would not do).
  const double sign = kappa > 0.0 ? 1.0 : -1.0;
  auto residual = [&](double x) { return std::log(sign * smoothed(build(sign * std::exp(x)))) - std::log(std::abs(kappa)); };
  double x0 = std::log(std::abs(kappa)), x1 = x0 - 0.1 * (1.0 + sigma * std::abs(kappa));
  double g0 = residual(x0), g1 = residual(x1);
  for (int it = 0; it < 100 && std::abs(g1) > 1e-13; ++it) {
    if (g1 == g0) break;
    const double x2 = x1 - g1 * (x1 - x0) / (g1 - g0);
    x0 = x1, g0 = g1;
    x1 = x2;
    g1 = residual(x1);
  }
  if (!(std::abs(g1) < 1e-9))
    throw InputError("start steering: no arc of curvature " + std::to_string(kappa) +
                     " 1/m after smoothing with sigma " + std::to_string(sigma) + " m");
  return build(sign * std::exp(x1));
}

}  // namespace

VehicleState Scenario::state(double t) const {
  JV p;
  JM C;
  evaluate(t, p, C);
  VehicleState s;
  s.t = t;
  s.p_inN = p.deriv(0);
  s.v_inN = p.deriv(1);
  s.a_inN = p.deriv(2);
  s.C_VtoN = C.value();
  s.omega_inV = body_rate(C);
  s.omega_dot_inV = body_rate_dot(C);
  return s;
}

double Scenario::distance(double t) const {
  double dist = 0.0;
  const double t0 = start_time();
  const int steps = std::max(1, static_cast<int>(std::ceil((t - t0) / 0.5)));
  const double h = (t - t0) / steps;
  for (int i = 0; i < steps; ++i) {
    const double mid = t0 + (i + 0.5) * h;
    for (int g = 0; g < 4; ++g) dist += 0.5 * h * kGlW[g] * state(mid + 0.5 * h * kGlX[g]).v_inN.norm();
  }
  return dist;
}

Terrain Terrain::gentle(double max_slope_deg, std::uint64_t seed) {
  // Three long waves in different directions (wavelengths 120-260 m); each wave's
  // slope amplitude is max_slope/3 * (0.8..1.2) so the total stays near the maximum.
  Terrain t;
  std::uint64_t x = seed * 0x9E3779B97F4A7C15ull + 0x1234567ull;
  auto next = [&x]() {
    x ^= x >> 12;
    x ^= x << 25;
    x ^= x >> 27;
    return static_cast<double>((x * 0x2545F4914F6CDD1Dull) >> 11) * 0x1.0p-53;
  };
  const double slope = std::tan(max_slope_deg * kDeg) / 3.0;
  for (int i = 0; i < 3; ++i) {
    const double lambda = 120.0 + 140.0 * next();
    const double dir = 2.0 * kPi * next();
    const double k = 2.0 * kPi / lambda;
    Wave w;
    w.amplitude = slope * (0.8 + 0.4 * next()) / k;
    w.kn = k * std::cos(dir);
    w.ke = k * std::sin(dir);
    w.phase = 2.0 * kPi * next();
    t.waves.push_back(w);
  }
  return t;
}

PathScenario::PathScenario(PathScenarioSpec spec) : spec_(std::move(spec)) {
  const auto& pts = spec_.path_ne;
  if (pts.size() < 2) throw InputError("scenario '" + spec_.name + "': the path needs at least two points");
  path_ = smoothed_path(pts, spec_.path_sigma);
  if (path_.knots().size() < 2) throw InputError("scenario '" + spec_.name + "': the path has no length");

  std::vector<std::array<double, 1>> pu;
  for (double x : spec_.profile_u) pu.push_back({x});
  profile_ = GaussPolyline<1>(spec_.profile_t, pu, spec_.profile_sigma, {0.0}, {0.0});
}

double PathScenario::polyline_length() const { return path_.knots().back(); }

J PathScenario::arc(double t) const {
  std::array<double, 1> d[kOrder + 1];
  profile_.eval(t, kOrder, d);
  J u;
  double fact = 1.0;
  for (int k = 0; k <= kOrder; ++k) {
    if (k > 0) fact *= k;
    u.c[k] = d[k][0] / fact;
  }
  return u;
}

void PathScenario::evaluate(double t, JV& p_inN, JM& C_VtoN) const {
  // u(t) and du/dt, both to full order.
  std::array<double, 1> ud[kOrder + 2];
  profile_.eval(t, kOrder + 1, ud);
  J u, udot;
  double fact = 1.0;
  for (int k = 0; k <= kOrder; ++k) {
    if (k > 0) fact *= k;
    u.c[k] = ud[k][0] / fact;
    udot.c[k] = ud[k + 1][0] / fact;
  }
  // Path derivatives with respect to u, up to what the jets need.
  std::array<double, 2> pd[kOrder + 3];
  path_.eval(u.value(), kOrder + 2, pd);
  auto comp = [&](int first, int dim) { return path_derivative(pd, first, dim, u); };
  const J pn = comp(0, 0), pe = comp(0, 1);
  const J xn = comp(1, 0), xe = comp(1, 1);  // dp/du
  J heading = atan2(xe, xn);
  if (spec_.skid_coeff != 0.0 || spec_.skid_angle != 0.0) {
    const J xnn = comp(2, 0), xee = comp(2, 1);  // d2p/du2
    const J m = sqrt(xn * xn + xe * xe);
    const J kappa = horizontal_curvature(xn, xe, xnn, xee);
    const J speed = m * udot;
    // v_y = -skid * speed^2 * kappa  <=>  heading = course + atan(skid * speed * kappa);
    // a tyre's slip angle grows with the lateral acceleration: + skid_angle * speed^2 * kappa.
    heading += atan(spec_.skid_coeff * speed * kappa) + spec_.skid_angle * speed * speed * kappa;
  }
  if (!spec_.terrain.enabled()) {
    p_inN = JV(pn, pe, J(0.0));
    C_VtoN = jrot_z(heading);
    return;
  }
  J H(0.0), Hn(0.0), He(0.0);
  for (const auto& w : spec_.terrain.waves) {
    J s, c;
    sincos(w.kn * pn + w.ke * pe + w.phase, s, c);
    H += w.amplitude * s;
    Hn += (w.amplitude * w.kn) * c;
    He += (w.amplitude * w.ke) * c;
  }
  p_inN = JV(pn, pe, -H);
  J ch, sh;
  sincos(heading, sh, ch);
  // x: the heading direction in the tangent plane; z: the downward surface normal.
  JV x(ch, sh, -(Hn * ch + He * sh));
  const J xnorm = sqrt(dot(x, x));
  x = JV(x[0] / xnorm, x[1] / xnorm, x[2] / xnorm);
  JV z(Hn, He, J(1.0));
  const J znorm = sqrt(dot(z, z));
  z = JV(z[0] / znorm, z[1] / znorm, z[2] / znorm);
  const JV y = cross(z, x);
  C_VtoN = JM::from_columns(x, y, z);
}

J PathScenario::path_curvature(double t) const {
  // kappa(u(t)): the curvature's u-derivatives from the path's, composed with u(t).
  const J u = arc(t);
  std::array<double, 2> pd[kOrder + 3];
  path_.eval(u.value(), kOrder + 2, pd);
  auto comp = [&](int first, int dim) { return path_derivative(pd, first, dim, u); };
  return horizontal_curvature(comp(1, 0), comp(1, 1), comp(2, 0), comp(2, 1));
}

double PathScenario::curvature_at(double u) const { return smoothed_curvature(path_, u); }

std::string PathScenario::describe() const {
  std::ostringstream os;
  os << spec_.name << ": polyline " << path_.knots().size() << " vertices, "
     << polyline_length() << " m, corner sigma " << spec_.path_sigma << " m, speed sigma "
     << spec_.profile_sigma << " s" << (spec_.terrain.enabled() ? ", terrain" : "")
     << (spec_.skid_coeff != 0.0 || spec_.skid_angle != 0.0 ? ", skid" : "");
  return os.str();
}

PathScenarioSpec default_scenario_spec(const DefaultScenarioOptions& opt) {
  PathScenarioSpec s;
  s.name = "default";
  s.origin = opt.origin;
  s.start_time = opt.start_time;
  s.path_sigma = opt.path_sigma;
  s.profile_sigma = opt.profile_sigma;
  s.skid_coeff = opt.skid_coeff;
  s.skid_angle = opt.skid_angle;
  s.terrain = opt.terrain;
  // T-shaped block driven clockwise (north up, east right before rotation): a 45 m x 10 m
  // stem and a 70 m x 12 m bar; 254 m per lap, six right and two left 90-degree turns.
  const std::vector<std::array<double, 2>> lap = {
      {5, -5}, {45, -5}, {45, -35}, {57, -35}, {57, 35}, {45, 35}, {45, 5}, {0, 5}, {0, -5}};
  const double c = std::cos(opt.rotation_deg * kDeg), sn = std::sin(opt.rotation_deg * kDeg);
  auto rot = [&](const std::array<double, 2>& q) {
    return std::array<double, 2>{opt.scale * (c * q[0] - sn * q[1]), opt.scale * (sn * q[0] + c * q[1])};
  };
  std::vector<std::array<double, 2>> pts;
  for (int l = 0; l < opt.laps; ++l)
    for (std::size_t i = (l == 0 ? 0 : 1); i < lap.size(); ++i) pts.push_back(rot(lap[i]));
  pts.push_back(rot(lap[0]));  // back to the start point
  double L = 0.0;
  for (std::size_t i = 1; i < pts.size(); ++i) L += std::hypot(pts[i][0] - pts[i - 1][0], pts[i][1] - pts[i - 1][1]);
  const double lap_len = L / opt.laps;
  // A start with the wheels turned: the arc before the T; o starts on it at arc length u0 of
  // the polyline and reaches the T's start point after `lead` metres.
  double u0 = 0.0, lead = 0.0;
  if (opt.start_curvature != 0.0) {
    const StartArc arc = start_arc(pts, opt.start_curvature, opt.path_sigma);
    pts.insert(pts.begin(), arc.vertices.begin(), arc.vertices.end());
    const GaussPolyline<2> path = smoothed_path(pts, opt.path_sigma);
    u0 = path.knots()[arc.start];
    lead = path.knots()[arc.vertices.size()] - u0;
    // Shift so that o starts at the origin (the smoothed path's point, not the vertex).
    std::array<double, 2> p0[1];
    path.eval(u0, 0, p0);
    for (auto& q : pts) q = {q[0] - p0[0][0], q[1] - p0[0][1]};
  } else {
    // Shift so the start point is the origin.
    const auto p0 = pts[0];
    for (auto& q : pts) q = {q[0] - p0[0], q[1] - p0[1]};
  }
  s.path_ne = pts;

  // Speed profile: piecewise-constant speed (integrated: piecewise-linear u), smoothed.
  // Motion starts 6 sigma after the static period so that it is static to ~1e-8 m/s^2.
  double t = opt.start_time + opt.static_duration + 6.0 * opt.profile_sigma;
  s.static_end = opt.start_time + opt.static_duration;
  s.profile_t = {opt.start_time, t};
  s.profile_u = {u0, u0};
  double u = u0;
  auto drive_to = [&](double target) {
    t += (target - u) / opt.speed;
    u = target;
    s.profile_t.push_back(t);
    s.profile_u.push_back(u);
  };
  auto dwell = [&](double secs) {
    t += secs;
    s.profile_t.push_back(t);
    s.profile_u.push_back(u);
  };
  for (int l = 1; l <= opt.laps; ++l) {
    drive_to(u0 + lead + l * lap_len);
    if (opt.stops && l < opt.laps && l % 2 == 0) dwell(opt.stop_duration);  // 15 s: ~8 s fully stopped
  }
  s.end_time = t + 6.0 * opt.profile_sigma + 20.0;
  s.profile_t.push_back(s.end_time);
  s.profile_u.push_back(u);
  return s;
}

SpeedSamples read_speed_file(const std::filesystem::path& file) {
  BinaryRowReader rd(file, 2);
  SpeedSamples s;
  while (const double* r = rd.next()) {
    const auto i = std::to_string(rd.index());
    if (!std::isfinite(r[0]) || !std::isfinite(r[1]))
      throw InputError(quote(file) + ": record " + i + ": non-finite value");
    if (!s.t.empty() && !(r[0] > s.t.back()))
      throw InputError(quote(file) + ": record " + i + ": time " + std::to_string(r[0]) +
                       " does not increase (previous " + std::to_string(s.t.back()) + ")");
    double v = r[1];
    if (v < -0.01)
      throw InputError(quote(file) + ": record " + i + ": negative speed " + std::to_string(v) +
                       " m/s (reversing is not supported by the path scenario)");
    if (v < 0.0) v = 0.0;
    if (v > 100.0)
      throw InputError(quote(file) + ": record " + i + ": speed " + std::to_string(v) +
                       " m/s is not plausible (expected column 2 = forward speed in m/s)");
    s.t.push_back(r[0]);
    s.v.push_back(v);
  }
  if (s.t.size() < 2) throw InputError(quote(file) + ": needs at least two (t, speed) records");
  return s;
}

namespace {

struct RawPoint {
  double a = 0.0, b = 0.0, h = 0.0;  // lat/lon [deg] or north/east [m]
};

std::vector<RawPoint> read_kml(const std::filesystem::path& file) {
  if (io_detail::check_input_file(file, "a KML path file") > (std::uint64_t{256} << 20))
    throw InputError(quote(file) + ": larger than 256 MiB: not a path file");
  std::ifstream in(file);
  if (!in) throw InputError(quote(file) + ": cannot open");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  const auto ls = text.find("<LineString");
  if (ls == std::string::npos) throw InputError(quote(file) + ": no <LineString> element");
  const auto c0 = text.find("<coordinates>", ls);
  const auto c1 = c0 == std::string::npos ? c0 : text.find("</coordinates>", c0);
  if (c0 == std::string::npos || c1 == std::string::npos)
    throw InputError(quote(file) + ": <LineString> without a complete <coordinates> element");
  std::istringstream body(text.substr(c0 + 13, c1 - c0 - 13));
  std::vector<RawPoint> pts;
  std::string tok;
  while (body >> tok) {
    double v[3] = {0, 0, 0};
    int n = 0;
    std::size_t pos = 0;
    bool ok = true;
    while (pos <= tok.size() && n < 3) {
      const auto comma = tok.find(',', pos);
      const std::string field = tok.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos);
      try {
        std::size_t used = 0;
        v[n] = std::stod(field, &used);
        if (used != field.size()) ok = false;
      } catch (const std::exception&) {
        ok = false;
      }
      ++n;
      if (comma == std::string::npos) break;
      pos = comma + 1;
    }
    if (!ok || n < 2 || !std::isfinite(v[0]) || !std::isfinite(v[1]))
      throw InputError(quote(file) + ": LineString coordinate " + std::to_string(pts.size()) +
                       " ('" + tok + "') is not lon,lat[,height]");
    if (std::abs(v[1]) > 90.0 || std::abs(v[0]) > 180.0)
      throw InputError(quote(file) + ": LineString coordinate " + std::to_string(pts.size()) +
                       ": lon " + std::to_string(v[0]) + ", lat " + std::to_string(v[1]) +
                       " out of range");
    pts.push_back({v[1], v[0], v[2]});
  }
  return pts;
}

/// CSV: columns lat,lon[,h] (degrees) or north,east (metres), chosen by a header line
/// (names lat/latitude, lon/lng/longitude, h/height/alt; north/n, east/e); without a
/// header: lat,lon. '#' starts a comment; separators: comma, semicolon, whitespace.
std::vector<RawPoint> read_csv(const std::filesystem::path& file, bool& local_metres) {
  io_detail::check_input_file(file, "a CSV path file");
  std::ifstream in(file);
  if (!in) throw InputError(quote(file) + ": cannot open");
  std::string line;
  int col_a = 0, col_b = 1, col_h = -1;
  local_metres = false;
  bool header_seen = false;
  std::vector<RawPoint> pts;
  int lineno = 0;
  auto split = [](std::string s) {
    for (char& ch : s)
      if (ch == ',' || ch == ';' || ch == '\t') ch = ' ';
    std::istringstream is(s);
    std::vector<std::string> f;
    std::string x;
    while (is >> x) f.push_back(x);
    return f;
  };
  while (io_detail::bounded_getline(in, line, io_detail::kMaxTextLine, quote(file))) {
    ++lineno;
    if (const auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    const auto f = split(line);
    if (f.empty()) continue;
    char* end = nullptr;
    std::strtod(f[0].c_str(), &end);
    const bool numeric = end && *end == '\0';
    if (!numeric) {
      if (header_seen || !pts.empty())
        throw InputError(quote(file) + ": line " + std::to_string(lineno) + ": not numeric: '" + line + "'");
      header_seen = true;
      col_a = col_b = col_h = -1;
      for (int i = 0; i < static_cast<int>(f.size()); ++i) {
        std::string k = f[i];
        std::transform(k.begin(), k.end(), k.begin(), [](unsigned char ch) { return std::tolower(ch); });
        if (k == "lat" || k == "latitude" || k == "lat_deg") col_a = i;
        else if (k == "lon" || k == "lng" || k == "longitude" || k == "lon_deg") col_b = i;
        else if (k == "h" || k == "height" || k == "alt" || k == "altitude") col_h = i;
        else if (k == "north" || k == "n" || k == "north_m") { col_a = i; local_metres = true; }
        else if (k == "east" || k == "e" || k == "east_m") { col_b = i; local_metres = true; }
      }
      if (col_a < 0 || col_b < 0)
        throw InputError(quote(file) + ": line " + std::to_string(lineno) +
                         ": header must name lat and lon, or north and east columns");
      continue;
    }
    const int need = std::max({col_a, col_b, col_h}) + 1;
    if (static_cast<int>(f.size()) < need)
      throw InputError(quote(file) + ": line " + std::to_string(lineno) + ": expected " +
                       std::to_string(need) + " columns");
    auto num = [&](int c) {
      char* e = nullptr;
      const double v = std::strtod(f[c].c_str(), &e);
      if (!e || *e != '\0' || !std::isfinite(v))
        throw InputError(quote(file) + ": line " + std::to_string(lineno) + ": column " +
                         std::to_string(c + 1) + " ('" + f[c] + "') is not a number");
      return v;
    };
    RawPoint p{num(col_a), num(col_b), col_h >= 0 ? num(col_h) : 0.0};
    if (!local_metres && (std::abs(p.a) > 90.0 || std::abs(p.b) > 180.0))
      throw InputError(quote(file) + ": line " + std::to_string(lineno) + ": lat " +
                       std::to_string(p.a) + ", lon " + std::to_string(p.b) + " out of range");
    pts.push_back(p);
  }
  return pts;
}

}  // namespace

PathScenarioSpec path_file_scenario_spec(const std::filesystem::path& path_file,
                                         const PathFileOptions& opt, double* speed_scale) {
  std::string ext = path_file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char ch) { return std::tolower(ch); });
  bool local = false;
  std::vector<RawPoint> raw;
  if (ext == ".kml") {
    raw = read_kml(path_file);
  } else if (ext == ".csv" || ext == ".txt") {
    raw = read_csv(path_file, local);
  } else {
    throw InputError(quote(path_file) + ": unknown path format (expected .kml or .csv)");
  }
  if (raw.size() < 2) throw InputError(quote(path_file) + ": the path needs at least two points");

  PathScenarioSpec s;
  s.name = path_file.filename().string();
  s.path_sigma = opt.path_sigma;
  s.profile_sigma = opt.profile_sigma;
  s.skid_coeff = opt.skid_coeff;
  s.skid_angle = opt.skid_angle;
  s.terrain = opt.terrain;
  std::vector<std::array<double, 2>> ne;
  if (local) {
    s.origin = opt.origin.value_or(earth::Geodetic{30.5285 * kDeg, 114.3573 * kDeg, 25.0});
    for (const auto& p : raw) ne.push_back({p.a - raw[0].a, p.b - raw[0].b});
  } else {
    const earth::Geodetic first{raw[0].a * kDeg, raw[0].b * kDeg, raw[0].h};
    s.origin = opt.origin.value_or(first);
    const earth::LocalFrame lf(s.origin);
    const Vec3 start = lf.ned_from_geodetic(first);
    for (const auto& p : raw) {
      const Vec3 q = lf.ned_from_geodetic({p.a * kDeg, p.b * kDeg, p.h});
      ne.push_back({q.x() - start.x(), q.y() - start.y()});
    }
  }
  // Drop GNSS jitter at rest: keep a vertex only min_spacing away from the last kept one.
  for (const auto& q : ne) {
    if (s.path_ne.empty() ||
        std::hypot(q[0] - s.path_ne.back()[0], q[1] - s.path_ne.back()[1]) >= opt.min_spacing)
      s.path_ne.push_back(q);
  }
  if (s.path_ne.size() < 2)
    throw InputError(quote(path_file) + ": the path has no length (all points within " +
                     std::to_string(opt.min_spacing) + " m)");
  double L = 0.0;
  for (std::size_t i = 1; i < s.path_ne.size(); ++i)
    L += std::hypot(s.path_ne[i][0] - s.path_ne[i - 1][0], s.path_ne[i][1] - s.path_ne[i - 1][1]);

  double scale = 1.0;
  if (opt.speed_file) {
    const SpeedSamples sp = read_speed_file(*opt.speed_file);
    std::vector<double> U{0.0};
    for (std::size_t i = 1; i < sp.t.size(); ++i)
      U.push_back(U.back() + 0.5 * (sp.v[i] + sp.v[i - 1]) * (sp.t[i] - sp.t[i - 1]));
    if (!(U.back() > 0.0))
      throw InputError(quote(*opt.speed_file) + ": the speed profile never moves");
    if (opt.fit_speed_to_path) scale = L / U.back();
    s.start_time = sp.t.front() - opt.static_duration;
    if (opt.static_duration > 0.0) {
      s.profile_t.push_back(s.start_time);
      s.profile_u.push_back(0.0);
    }
    for (std::size_t i = 0; i < sp.t.size(); ++i) {
      s.profile_t.push_back(sp.t[i]);
      s.profile_u.push_back(U[i] * scale);
    }
    s.end_time = sp.t.back() + opt.static_after;
    if (opt.static_after > 0.0) {
      s.profile_t.push_back(s.end_time);
      s.profile_u.push_back(U.back() * scale);
    }
    s.static_end = std::max(s.start_time, sp.t.front() - 5.0 * opt.profile_sigma);
  } else {
    s.start_time = opt.start_time;
    const double t1 = s.start_time + opt.static_duration + 6.0 * opt.profile_sigma;
    const double t2 = t1 + L / opt.speed;
    s.end_time = t2 + 6.0 * opt.profile_sigma + opt.static_after;
    s.profile_t = {s.start_time, t1, t2, s.end_time};
    s.profile_u = {0.0, 0.0, L, L};
    s.static_end = s.start_time + opt.static_duration;
  }
  if (speed_scale) *speed_scale = scale;
  return s;
}

}  // namespace wheelins::sim
