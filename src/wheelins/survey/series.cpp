// Reading a module's file into an evenly spaced series of mean rates (series.hpp).
#include "wheelins/survey/series.hpp"

#include <algorithm>
#include <cmath>

namespace wheelins::survey {

std::size_t Series::index(double t) const {
  if (gyro.empty()) return 0;
  const double k = std::floor((t - t0) / dt);
  if (!(k > 0.0)) return 0;
  return std::min(static_cast<std::size_t>(k), gyro.size() - 1);
}

Series read_series(const std::string& module, const std::filesystem::path& file,
                   const ImuReadOptions& read, const SeriesOptions& o) {
  Series s;
  s.module = module;
  s.file = file;
  s.dt = o.bin;
  ImuFileReader reader(file, read);
  std::vector<double> time_sum;  // sum of dt per bin (the mean rate is sum(dtheta) / sum(dt))
  ImuSample x;
  bool started = false;
  while (reader.next(x)) {
    if (x.t < o.skip_before) continue;
    if (!started) {
      s.t0 = x.t - 0.5 * o.bin;
      s.t_first = x.t;
      started = true;
    }
    s.t_end = x.t;
    if (s.truncated) continue;  // read through for the last record's time only
    if (x.t - s.t_first > o.max_span || s.samples >= o.max_samples) {
      s.truncated = true;
      continue;
    }
    ++s.samples;
    if (!(x.dt > 0.0) || !x.dtheta.allFinite() || !x.dvel.allFinite() ||
        !((x.dtheta / x.dt).cwiseAbs().maxCoeff() <= o.gyro_limit) ||
        !((x.dvel / x.dt).cwiseAbs().maxCoeff() <= o.accel_limit)) {
      ++s.left_out;
      continue;
    }
    s.t_last = x.t;
    const std::size_t k = static_cast<std::size_t>(std::floor((x.t - s.t0) / o.bin));
    if (k >= s.gyro.size()) {
      s.gyro.resize(k + 1, Vec3::Zero());
      s.accel.resize(k + 1, Vec3::Zero());
      time_sum.resize(k + 1, 0.0);
    }
    s.gyro[k] += x.dtheta;
    s.accel[k] += x.dvel;
    time_sum[k] += x.dt;
  }
  const std::size_t n = s.gyro.size();
  s.filled.assign(n, 0);
  for (std::size_t k = 0; k < n; ++k)
    if (time_sum[k] > 0.0) {
      s.gyro[k] /= time_sum[k];
      s.accel[k] /= time_sum[k];
      s.filled[k] = 1;
    }
  // Empty bins: the straight line between the filled neighbours.
  std::size_t prev = n;
  for (std::size_t k = 0; k < n; ++k) {
    if (!s.filled[k]) continue;
    if (prev != n && k > prev + 1)
      for (std::size_t j = prev + 1; j < k; ++j) {
        const double a = static_cast<double>(j - prev) / static_cast<double>(k - prev);
        s.gyro[j] = (1.0 - a) * s.gyro[prev] + a * s.gyro[k];
        s.accel[j] = (1.0 - a) * s.accel[prev] + a * s.accel[k];
      }
    prev = k;
  }
  return s;
}

double sample_at(const Series& s, const std::vector<double>& signal, double t) {
  if (signal.empty()) return 0.0;
  const double u = (t - s.t0) / s.dt - 0.5;
  if (!(u > 0.0)) return signal.front();
  const double last = static_cast<double>(signal.size() - 1);
  if (u >= last) return signal.back();
  const std::size_t k = static_cast<std::size_t>(u);
  const double a = u - static_cast<double>(k);
  return (1.0 - a) * signal[k] + a * signal[k + 1];
}

std::vector<double> moving_average(const std::vector<double>& x, int n) {
  const std::size_t N = x.size();
  std::vector<double> out(N, 0.0);
  if (N == 0 || n <= 1) return x;
  std::vector<double> c(N + 1, 0.0);
  for (std::size_t i = 0; i < N; ++i) c[i + 1] = c[i] + x[i];
  const std::size_t h = static_cast<std::size_t>(n / 2);
  for (std::size_t i = 0; i < N; ++i) {
    const std::size_t lo = i >= h ? i - h : 0, hi = std::min(N, i + h + 1);
    out[i] = (c[hi] - c[lo]) / static_cast<double>(hi - lo);
  }
  return out;
}

}  // namespace wheelins::survey
