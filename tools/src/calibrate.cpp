// `trm calibrate`: simulated photometer readings of alternating drive pairs, and the Eq. 7 least-squares fit.
//
// The solver is Eigen's Levenberg–Marquardt (unsupported/Eigen/NonLinearOptimization, the MINPACK lmder port) rather
// than Ceres: five parameters and at most a few thousand residuals with a Jacobian written out in five lines need no
// automatic differentiation or sparse linear algebra, and Eigen is header-only (Ceres brings glog, gflags and
// SuiteSparse as shared libraries).
#include "calibrate.hpp"

#include "trm/panel_light.hpp"

#include <Eigen/Core>
#include <unsupported/Eigen/NonLinearOptimization>

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <stdexcept>

namespace trm::cli {

namespace {

[[noreturn]] void reject_option(const std::string& option, const std::string& why) {
  throw std::invalid_argument("trm calibrate: " + option + " " + why);
}

std::string text(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

// Readings so small that the photometer cannot see them still count; only their sign and finiteness are checked.
void require_readings(const std::vector<PairReading>& readings) {
  if (readings.size() < 6) {
    throw std::invalid_argument("fit_eq7: needs at least 6 readings (Eq. 7 and gamma have 5 parameters), got " +
                                std::to_string(readings.size()));
  }
  for (const PairReading& r : readings) {
    for (double value : {r.v_t, r.v_prev, r.luminance}) {
      if (!std::isfinite(value)) throw std::invalid_argument("fit_eq7: readings must be finite, got " + text(value));
    }
    if (r.luminance < 0.0) throw std::invalid_argument("fit_eq7: luminance must be >= 0, got " + text(r.luminance));
    if (r.v_t < 0.0 || r.v_t > 1.0 || r.v_prev < 0.0 || r.v_prev > 1.0) {
      throw std::invalid_argument("fit_eq7: drive values must be in [0, 1]");
    }
  }
}

// The decoders invert M in v_t, so the fit must keep dM/dv_t = 2 p1 v_t + p2 v_prev + p3 > 0 on [0, 1]² (and the
// held merge rising, which the same corners cover): linear in (v_t, v_prev), its minimum is at a corner. A panel whose
// alternation is almost flat in v_t near a corner (a slow fall after white) pulls an unconstrained fit below zero
// there; a penalty row per corner keeps each corner's slope at kMinSlope or more.
constexpr double kMinSlope = 1e-3;
constexpr double kPenaltyWeight = 1e3;
constexpr int kCorners = 4;

// dM/dv_t at the corners (v_t, v_prev) = (0, 0), (1, 0), (0, 1), (1, 1) and its gradient in (p1, p2, p3).
double corner_slope(const Eigen::VectorXd& x, int corner) {
  const double v_t = corner & 1, v_prev = corner >> 1;
  return 2.0 * x[0] * v_t + x[1] * v_prev + x[2];
}

// Y = max(M, 0)^γ over x = (p1, p2, p3, p4, γ), residuals model − reading, with the analytic Jacobian, then the
// corner penalties.
struct Eq7Residuals {
  using Scalar = double;
  enum { InputsAtCompileTime = Eigen::Dynamic, ValuesAtCompileTime = Eigen::Dynamic };
  using InputType = Eigen::VectorXd;
  using ValueType = Eigen::VectorXd;
  using JacobianType = Eigen::MatrixXd;

  const std::vector<PairReading>* readings = nullptr;

  int inputs() const { return 5; }
  int readings_count() const { return static_cast<int>(readings->size()); }
  int values() const { return readings_count() + kCorners; }

  static double merge(const Eigen::VectorXd& x, double a, double b) {
    return x[0] * (a * a + b * b) + x[1] * a * b + x[2] * (a + b) + x[3];
  }

  int operator()(const Eigen::VectorXd& x, Eigen::VectorXd& fvec) const {
    for (int k = 0; k < readings_count(); ++k) {
      const PairReading& r = (*readings)[static_cast<std::size_t>(k)];
      fvec[k] = std::pow(std::max(merge(x, r.v_t, r.v_prev), 0.0), x[4]) - r.luminance;
    }
    for (int c = 0; c < kCorners; ++c) {
      fvec[readings_count() + c] = kPenaltyWeight * std::min(0.0, corner_slope(x, c) - kMinSlope);
    }
    return 0;
  }

  int df(const Eigen::VectorXd& x, Eigen::MatrixXd& jac) const {
    for (int c = 0; c < kCorners; ++c) {
      const int row = readings_count() + c;
      jac.row(row).setZero();
      if (corner_slope(x, c) >= kMinSlope) continue;
      jac(row, 0) = kPenaltyWeight * 2.0 * (c & 1);
      jac(row, 1) = kPenaltyWeight * (c >> 1);
      jac(row, 2) = kPenaltyWeight;
    }
    for (int k = 0; k < readings_count(); ++k) {
      const PairReading& r = (*readings)[static_cast<std::size_t>(k)];
      const double a = r.v_t, b = r.v_prev, m = merge(x, a, b);
      if (!(m > 0.0)) {
        jac.row(k).setZero();
        continue;
      }
      const double slope = x[4] * std::pow(m, x[4] - 1.0);
      jac(k, 0) = slope * (a * a + b * b);
      jac(k, 1) = slope * a * b;
      jac(k, 2) = slope * (a + b);
      jac(k, 3) = slope;
      jac(k, 4) = std::pow(m, x[4]) * std::log(m);
    }
    return 0;
  }
};

// Y = v^γ over the held readings (v, v): the single-frame model's γ.
struct HeldGammaResiduals {
  using Scalar = double;
  enum { InputsAtCompileTime = Eigen::Dynamic, ValuesAtCompileTime = Eigen::Dynamic };
  using InputType = Eigen::VectorXd;
  using ValueType = Eigen::VectorXd;
  using JacobianType = Eigen::MatrixXd;

  std::vector<PairReading> held;

  int inputs() const { return 1; }
  int values() const { return static_cast<int>(held.size()); }
  int operator()(const Eigen::VectorXd& x, Eigen::VectorXd& fvec) const {
    for (int k = 0; k < values(); ++k) fvec[k] = std::pow(held[k].v_t, x[0]) - held[k].luminance;
    return 0;
  }
  int df(const Eigen::VectorXd& x, Eigen::MatrixXd& jac) const {
    for (int k = 0; k < values(); ++k) {
      const double v = held[k].v_t;
      jac(k, 0) = v > 0.0 ? std::pow(v, x[0]) * std::log(v) : 0.0;
    }
    return 0;
  }
};

template <typename Functor>
int minimise(Functor& functor, Eigen::VectorXd& x, const char* what) {
  Eigen::LevenbergMarquardt<Functor> lm(functor);
  lm.parameters.ftol = 1e-15;
  lm.parameters.xtol = 1e-15;
  lm.parameters.maxfev = 2000;
  const Eigen::LevenbergMarquardtSpace::Status status = lm.minimize(x);
  if (status == Eigen::LevenbergMarquardtSpace::ImproperInputParameters ||
      status == Eigen::LevenbergMarquardtSpace::TooManyFunctionEvaluation || !x.allFinite()) {
    throw std::runtime_error(std::string("trm calibrate: the ") + what + " fit did not converge (status " +
                             std::to_string(static_cast<int>(status)) + " after " + std::to_string(lm.nfev) +
                             " evaluations)");
  }
  return static_cast<int>(lm.iter);
}

void summarise(const std::vector<double>& residuals, double& rms, double& max_abs) {
  double sum = 0.0;
  max_abs = 0.0;
  for (double r : residuals) {
    sum += r * r;
    max_abs = std::max(max_abs, std::abs(r));
  }
  rms = std::sqrt(sum / static_cast<double>(residuals.size()));
}

}  // namespace

void CalibrationOptions::validate() const {
  if (!(std::isfinite(refresh_hz) && refresh_hz > 0.0)) reject_option("--refresh", "must be > 0, got " + text(refresh_hz));
  if (grid < 3 || grid > 64) reject_option("--grid", "must be in [3, 64], got " + std::to_string(grid));
  if (!(std::isfinite(window_s) && window_s * refresh_hz >= 2.0)) {
    reject_option("--window", "must hold at least one pair of frames (>= 2 / refresh), got " + text(window_s));
  }
  if (!(std::isfinite(warmup_s) && warmup_s >= 0.0)) reject_option("--warmup", "must be >= 0, got " + text(warmup_s));
  if (!(noise >= 0.0 && noise < 0.5)) reject_option("--noise", "must be in [0, 0.5), got " + text(noise));
  if (!(native_gamma >= kMinPanelGamma && native_gamma <= kMaxPanelGamma)) {
    reject_option("--native-gamma", "must be in [" + text(kMinPanelGamma) + ", " + text(kMaxPanelGamma) + "], got " +
                                        text(native_gamma));
  }
  LcResponse(lc, 1.0 / refresh_hz);  // throws naming the LC field
}

std::vector<PairReading> measure_pairs(const CalibrationOptions& options) {
  options.validate();
  PanelLightConfig config;
  config.refresh_hz = options.refresh_hz;
  config.lc_response = options.lc;
  config.overdrive = options.overdrive;
  const PanelLight light(config);
  const double period = light.frame_period_s();
  // Whole pairs of frames, so that the window holds as many v_t as v_{t−1} frames.
  const auto pairs_in = [&](double seconds) { return static_cast<long>(std::floor(seconds / period / 2.0)); };
  const long warmup_pairs = pairs_in(options.warmup_s), window_pairs = std::max(1L, pairs_in(options.window_s));
  std::mt19937_64 random(options.seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::vector<PairReading> readings;
  for (int j = 0; j < options.grid; ++j) {
    for (int i = 0; i < options.grid; ++i) {
      const double v_t = double(i) / (options.grid - 1), v_prev = double(j) / (options.grid - 1);
      const double level_t = std::pow(v_t, options.native_gamma), level_prev = std::pow(v_prev, options.native_gamma);
      double state = level_prev;  // held at v_{t−1} before the alternation starts with v_t
      const auto show = [&](double level) {
        const double light_in_frame = light.integral(0.0, period, state, level);
        state = light.end_state(state, level);
        return light_in_frame;
      };
      for (long p = 0; p < warmup_pairs; ++p) {
        show(level_t);
        show(level_prev);
      }
      double sum = 0.0;
      for (long p = 0; p < window_pairs; ++p) sum += show(level_t) + show(level_prev);
      double luminance = sum / (2.0 * window_pairs * period);
      if (options.noise > 0.0) luminance = std::max(0.0, luminance * (1.0 + options.noise * gauss(random)));
      readings.push_back({v_t, v_prev, luminance});
    }
  }
  return readings;
}

Eq7Fit fit_eq7(const std::vector<PairReading>& readings, const LcdPanel& start) {
  require_readings(readings);
  Eq7Fit fit;
  Eq7Residuals residuals;
  residuals.readings = &readings;
  Eigen::VectorXd x(5);
  x << start.p1, start.p2, start.p3, start.p4, start.gamma;
  fit.iterations = minimise(residuals, x, "Eq. 7");
  fit.panel.p1 = x[0];
  fit.panel.p2 = x[1];
  fit.panel.p3 = x[2];
  fit.panel.p4 = x[3];
  fit.panel.gamma = x[4];
  try {
    fit.panel.validate("");
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error("trm calibrate: the fitted merge (p1 " + text(x[0]) + ", p2 " + text(x[1]) + ", p3 " +
                             text(x[2]) + ", p4 " + text(x[3]) + ", gamma " + text(x[4]) +
                             ") is no invertible panel: " + e.what());
  }
  Eigen::VectorXd f(residuals.values());
  residuals(x, f);
  for (int k = 0; k < residuals.readings_count(); ++k) fit.residuals.push_back(-f[k]);
  for (int c = 0; c < kCorners; ++c) fit.slope_constrained = fit.slope_constrained || corner_slope(x, c) < 2 * kMinSlope;
  summarise(fit.residuals, fit.rms, fit.max_abs);

  HeldGammaResiduals held;
  for (const PairReading& r : readings) {
    if (r.v_t == r.v_prev) held.held.push_back(r);
  }
  if (held.held.size() >= 2) {
    Eigen::VectorXd g(1);
    g << start.gamma;
    minimise(held, g, "held gamma");
    fit.plain_gamma = g[0];
    for (const PairReading& r : readings) {
      const double plain = (std::pow(r.v_t, g[0]) + std::pow(r.v_prev, g[0])) / 2.0;
      fit.plain_residuals.push_back(r.luminance - plain);
    }
    summarise(fit.plain_residuals, fit.plain_rms, fit.plain_max_abs);
  }
  return fit;
}

std::string readings_csv(const std::vector<PairReading>& readings, const Eq7Fit& fit) {
  std::ostringstream out;
  out.precision(10);
  out << "v_t,v_prev,luminance,eq7_residual,plain_residual\n";
  for (std::size_t k = 0; k < readings.size(); ++k) {
    out << readings[k].v_t << "," << readings[k].v_prev << "," << readings[k].luminance << ","
        << (k < fit.residuals.size() ? fit.residuals[k] : 0.0) << ","
        << (k < fit.plain_residuals.size() ? fit.plain_residuals[k] : 0.0) << "\n";
  }
  return out.str();
}

}  // namespace trm::cli
