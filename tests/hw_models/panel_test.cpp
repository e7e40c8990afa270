// Panel models: preset parsing, OLED gamma round trip, the LCD merge (Eq. 7) and its stable inverse, the panel
// model's drive and emission against each other and against values worked out by hand, and its JSON.
#include "trm/panel.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace trm {
namespace {

// Independent oracle for a merge that increases in v_t on [0, 1]: plain bisection on M(v, v_prev) = m.
double bisect_monotone(const LcdPanel& lcd, double m, double v_prev) {
  double lo = 0.0;
  double hi = 1.0;
  for (int i = 0; i < 200 && hi - lo > 0.0; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (mid == lo || mid == hi) break;
    (lcd.merge(mid, v_prev) < m ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

LcdPanel lcd_with(double p1, double p2, double p3, double p4) {
  LcdPanel lcd;
  lcd.p1 = p1;
  lcd.p2 = p2;
  lcd.p3 = p3;
  lcd.p4 = p4;
  return lcd;
}

TEST(ParsePanel, OledPresetsCarryTheMeasuredGammas) {
  const Panel vive = parse_panel("vive");
  EXPECT_EQ(vive.kind, PanelKind::Oled);
  EXPECT_EQ(vive.oled.gamma, (std::array<double, 3>{2.2912, 2.2520, 2.1940}));
  EXPECT_DOUBLE_EQ(vive.oled.duty, 0.2);

  const Panel rift = parse_panel("rift");
  EXPECT_EQ(rift.kind, PanelKind::Oled);
  EXPECT_EQ(rift.oled.gamma, (std::array<double, 3>{2.1526, 2.0910, 2.0590}));
  EXPECT_DOUBLE_EQ(rift.oled.duty, 0.2);

  EXPECT_EQ(parse_panel("generic").oled.gamma, (std::array<double, 3>{2.2, 2.2, 2.2}));
  EXPECT_EQ(parse_panel("gamma:2.4").oled.gamma, (std::array<double, 3>{2.4, 2.4, 2.4}));
  EXPECT_EQ(parse_panel("gamma:2.1,2.2,2.3").oled.gamma, (std::array<double, 3>{2.1, 2.2, 2.3}));
  EXPECT_EQ(parse_panel("gamma:2.4").name, "gamma:2.4");
}

TEST(ParsePanel, LcdDefaultsAndCustomParameters) {
  const Panel lcd = parse_panel("lcd");
  EXPECT_EQ(lcd.kind, PanelKind::Lcd);
  EXPECT_DOUBLE_EQ(lcd.lcd.p1, -0.1);
  EXPECT_DOUBLE_EQ(lcd.lcd.p2, 0.2);
  EXPECT_DOUBLE_EQ(lcd.lcd.p3, 0.5);
  EXPECT_DOUBLE_EQ(lcd.lcd.p4, 0.0);
  EXPECT_DOUBLE_EQ(lcd.lcd.gamma, 2.2);

  const Panel custom = parse_panel("lcd:-0.05,0.1,0.5,0.01,2.4");
  EXPECT_EQ(custom.kind, PanelKind::Lcd);
  EXPECT_DOUBLE_EQ(custom.lcd.p1, -0.05);
  EXPECT_DOUBLE_EQ(custom.lcd.p2, 0.1);
  EXPECT_DOUBLE_EQ(custom.lcd.p3, 0.5);
  EXPECT_DOUBLE_EQ(custom.lcd.p4, 0.01);
  EXPECT_DOUBLE_EQ(custom.lcd.gamma, 2.4);
}

TEST(ParsePanel, RejectsBadSpecsNamingTheAcceptedForms) {
  for (const char* bad : {"", "oled", "VIVE", "gamma:", "gamma:0", "gamma:-2.2", "gamma:2.2,2.2",
                          "gamma:2.2,,2.2", "gamma:2.2x", "gamma:nan", "gamma:inf", "lcd:", "lcd:1,2,3",
                          "lcd:nan,0.2,0.5,0,2.2", "lcd:-0.1,0.2,0.5,0,0", "lcd:-0.1,0.2,0.5,0,-2.2",
                          "lcd:-0.1,0.2,0.5,0,2.2,1", "lcd:-0.1,0.2,0.5,inf,2.2"}) {
    SCOPED_TRACE(bad);
    try {
      parse_panel(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const std::invalid_argument& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find("accepted panel specs"), std::string::npos) << message;
      EXPECT_NE(message.find("lcd:p1,p2,p3,p4,gamma"), std::string::npos) << message;
    }
  }
}

TEST(ParsePanel, RejectionSaysWhatIsWrong) {
  const auto message_of = [](const char* spec) {
    try {
      parse_panel(spec);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(message_of("lcd:nan,0.2,0.5,0,2.2").find("finite"), std::string::npos);
  EXPECT_NE(message_of("lcd:-0.1,0.2,0.5,0,0").find("gamma must be > 0"), std::string::npos);
  EXPECT_NE(message_of("gamma:0").find("> 0"), std::string::npos);
}

TEST(OledPanel, DriveIsTheInverseGammaPerChannel) {
  const Panel vive = parse_panel("vive");
  for (int channel = 0; channel < 3; ++channel) {
    const double gamma = vive.oled.gamma[static_cast<std::size_t>(channel)];
    for (int k = 0; k <= 100; ++k) {
      const double x = k / 100.0;
      const double v = vive.drive_from_linear(x, channel);
      EXPECT_NEAR(v, std::pow(x, 1.0 / gamma), 1e-15);
      EXPECT_NEAR(vive.linear_from_drive(v, channel), x, 1e-14);
    }
  }
  // The channels differ: red has the steepest gamma, so mid grey needs the highest red drive.
  EXPECT_GT(vive.drive_from_linear(0.5, 0), vive.drive_from_linear(0.5, 2));
  // Out-of-range linear input is clamped to the displayable range.
  EXPECT_EQ(vive.drive_from_linear(1.5, 1), 1.0);
  EXPECT_EQ(vive.drive_from_linear(-0.5, 1), 0.0);
}

// The row drives (a vector pow per chunk) against the per-sample ones, bit for bit: run lengths across the chunk
// sizes, values in and outside [0, 1], zeros, NaN, and (LCD) unreachable targets.
std::vector<double> drive_inputs(std::size_t n, std::uint64_t seed) {
  std::vector<double> x(n);
  for (std::size_t k = 0; k < n; ++k) {
    seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
    const double u = std::ldexp(static_cast<double>(seed >> 11), -53);
    x[k] = k % 97 == 5 ? std::nan("") : k % 13 == 0 ? 0.0 : k % 11 == 0 ? 1.0 : -0.2 + 1.4 * u;
  }
  return x;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(OledPanel, RowDriveIsThePerSampleDriveBitForBit) {
  const Panel vive = parse_panel("vive");
  for (const std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{7}, std::size_t{255}, std::size_t{256},
                              std::size_t{6480}}) {
    const std::vector<double> x = drive_inputs(n, n + 1);
    std::vector<double> v(n);
    vive.oled.drive(x, v);
    for (std::size_t k = 0; k < n; ++k) {
      ASSERT_TRUE(same_bits(v[k], vive.oled.drive(x[k], static_cast<int>(k % 3)))) << "n " << n << " k " << k;
    }
  }
  std::vector<double> shorter(3);
  EXPECT_THROW(vive.oled.drive(std::vector<double>(4), shorter), std::invalid_argument);
}

TEST(LcdPanel, RowDriveIsThePerSampleDriveBitForBit) {
  for (const LcdPanel& lcd : {LcdPanel{}, lcd_with(0.3, -0.2, 0.45, 0.02), lcd_with(0.0, 0.0, 0.5, 0.0)}) {
    for (const std::size_t n : {std::size_t{1}, std::size_t{255}, std::size_t{257}, std::size_t{6480}}) {
      const std::vector<double> x_t = drive_inputs(n, 3 * n);
      const std::vector<double> x_prev = drive_inputs(n, 5 * n + 1);
      std::vector<double> v_prev = drive_inputs(n, 7 * n + 2);
      for (double& v : v_prev) v = std::isnan(v) ? 0.5 : std::clamp(v, 0.0, 1.0);
      std::vector<PanelDriveSample> row(n);
      lcd.drive(x_t, x_prev, v_prev, row);
      std::size_t unreachable = 0;
      for (std::size_t k = 0; k < n; ++k) {
        const PanelDriveSample one = lcd.drive(x_t[k], x_prev[k], v_prev[k]);
        ASSERT_TRUE(same_bits(row[k].v, one.v) && same_bits(row[k].target, one.target) &&
                    same_bits(row[k].contributed, one.contributed) && row[k].reachable == one.reachable)
            << "n " << n << " k " << k;
        unreachable += one.reachable ? 0 : 1;
      }
      if (n == 6480) {
        EXPECT_GT(unreachable, 0U);
      }
    }
  }
  std::vector<PanelDriveSample> out(2);
  const std::vector<double> two(2);
  EXPECT_THROW(LcdPanel{}.drive(two, std::vector<double>(3), two, out), std::invalid_argument);
}

TEST(LcdPanel, MergeMatchesEquation7) {
  const LcdPanel lcd = lcd_with(0.3, -0.2, 0.7, 0.05);
  const double vt = 0.6;
  const double vp = 0.25;
  EXPECT_DOUBLE_EQ(lcd.merge(vt, vp), 0.3 * (0.36 + 0.0625) - 0.2 * 0.15 + 0.7 * 0.85 + 0.05);
}

TEST(LcdPanel, DefaultsMergeAHeldValueToItself) {
  const LcdPanel lcd;
  for (int k = 0; k <= 256; ++k) {
    const double v = k / 256.0;
    EXPECT_NEAR(lcd.merge(v, v), v, 1e-15);
  }
  // The default merge is M = p1 (vt - vp)^2 + (vt + vp) / 2: the transitions lose a little.
  EXPECT_NEAR(lcd.merge(1.0, 0.0), 0.4, 1e-15);
  EXPECT_NEAR(lcd.merge(0.0, 1.0), 0.4, 1e-15);
}

TEST(LcdPanel, InverseRoundTripsWhereReachableAndAgreesWithBisection) {
  const LcdPanel lcd;
  int reachable_count = 0;
  for (int j = 0; j <= 64; ++j) {
    const double vp = j / 64.0;
    // The default merge increases in v_t, so the reachable range is [M(0, vp), M(1, vp)].
    const double lowest = lcd.merge(0.0, vp);
    const double highest = lcd.merge(1.0, vp);
    for (int k = 0; k <= 200; ++k) {
      const double m = -0.1 + 1.2 * k / 200.0;
      SCOPED_TRACE(testing::Message() << "m=" << m << " vp=" << vp);
      const LcdPanel::Solution s = lcd.solve(m, vp);
      ASSERT_GE(s.v, 0.0);
      ASSERT_LE(s.v, 1.0);
      if (m >= lowest && m <= highest) {
        ++reachable_count;
        EXPECT_TRUE(s.reachable);
        EXPECT_NEAR(lcd.merge(s.v, vp), m, 1e-12);
        EXPECT_NEAR(s.v, bisect_monotone(lcd, m, vp), 1e-12);
      } else {
        EXPECT_FALSE(s.reachable);
        EXPECT_EQ(s.v, m < lowest ? 0.0 : 1.0);
      }
    }
  }
  EXPECT_GT(reachable_count, 5000);  // the grid exercises the reachable region well
}

TEST(LcdPanel, ExactlyLinearMergeUsesTheLinearSolve) {
  // p1 = 0: M = p2 vt vp + p3 (vt + vp) + p4, linear in vt.
  const LcdPanel lcd = lcd_with(0.0, 0.1, 0.45, 0.02);
  for (double vp : {0.0, 0.3, 1.0}) {
    for (double v_true : {0.0, 0.1, 0.5, 0.9, 1.0}) {
      const double m = lcd.merge(v_true, vp);
      const double linear_root = (m - 0.45 * vp - 0.02) / (0.1 * vp + 0.45);
      const LcdPanel::Solution s = lcd.solve(m, vp);
      EXPECT_TRUE(s.reachable);
      EXPECT_NEAR(s.v, linear_root, 1e-15);
      EXPECT_NEAR(s.v, v_true, 1e-15);
      EXPECT_FALSE(std::signbit(s.v));
    }
  }
}

TEST(LcdPanel, NearlyLinearMergeHasNoCatastrophicCancellation) {
  // With tiny p1 the textbook (-b + sqrt(b^2 - 4ac)) / 2a loses about |log10(p1)| digits; the stable form
  // must stay on the root next to the linear one and hit m to rounding.
  for (double p1 : {1e-12, -1e-9, 1e-15, -1e-14}) {
    const LcdPanel lcd = lcd_with(p1, -2.0 * p1, 0.5, 0.0);
    for (double vp : {0.0, 0.2, 0.7, 1.0}) {
      for (double v_true : {0.05, 0.3, 0.6, 0.95}) {
        SCOPED_TRACE(testing::Message() << "p1=" << p1 << " vp=" << vp << " v=" << v_true);
        const double m = lcd.merge(v_true, vp);
        const double linear_root = (m - 0.5 * vp) / 0.5;  // the p1 = 0 solution for the same m
        const LcdPanel::Solution s = lcd.solve(m, vp);
        EXPECT_TRUE(s.reachable);
        EXPECT_NEAR(s.v, v_true, 1e-15);
        EXPECT_NEAR(s.v, linear_root, 4.0 * std::abs(p1));  // the root moves by O(p1) only
        EXPECT_NEAR(lcd.merge(s.v, vp), m, 1e-15);
        EXPECT_NEAR(s.v, bisect_monotone(lcd, m, vp), 1e-15);
      }
    }
  }
  // The check above is sharp enough to see the cancellation it guards against.
  const double a = 1e-12;
  const double b = 0.5;
  const double c = -0.3 * b - a * 0.09;  // root 0.3
  const double textbook = (-b + std::sqrt(b * b - 4.0 * a * c)) / (2.0 * a);
  EXPECT_GT(std::abs(textbook - 0.3), 1e-8);
  EXPECT_NEAR(lcd_with(a, 0.0, 0.5, 0.0).solve(0.5 * 0.3 + a * 0.09, 0.0).v, 0.3, 1e-15);
}

TEST(LcdPanel, TwoRootsInRangePicksTheBranchContinuousWithTheLinearSolve) {
  // M(v, 0) = -v^2 + v: m = 0.16 has roots 0.2 and 0.8. As p1 -> 0 the solution tends to m / p3 = 0.16,
  // which the 0.2 root continues; 0.8 runs off to infinity.
  const LcdPanel lcd = lcd_with(-1.0, 0.0, 1.0, 0.0);
  const LcdPanel::Solution s = lcd.solve(0.16, 0.0);
  EXPECT_TRUE(s.reachable);
  EXPECT_NEAR(s.v, 0.2, 1e-15);
}

TEST(LcdPanel, NoRealRootClampsToTheVertex) {
  // M(v, 0) = v^2 - v has its minimum -0.25 at v = 0.5; m = -0.5 has no real root.
  const LcdPanel lcd = lcd_with(1.0, 0.0, -1.0, 0.0);
  const LcdPanel::Solution s = lcd.solve(-0.5, 0.0);
  EXPECT_FALSE(s.reachable);
  EXPECT_DOUBLE_EQ(s.v, 0.5);
  // Tangent: m = -0.25 touches the vertex, reachable.
  const LcdPanel::Solution tangent = lcd.solve(-0.25, 0.0);
  EXPECT_TRUE(tangent.reachable);
  EXPECT_NEAR(tangent.v, 0.5, 1e-7);
}

TEST(LcdPanel, RootsOutsideTheRangeClampToTheClosestEnd) {
  // M(v, 0) = v^2: m = 4 has roots +-2, both outside [0, 1]; M(1) = 1 is the closest.
  const LcdPanel squares = lcd_with(1.0, 0.0, 0.0, 0.0);
  const LcdPanel::Solution high = squares.solve(4.0, 0.0);
  EXPECT_FALSE(high.reachable);
  EXPECT_EQ(high.v, 1.0);

  // Defaults from black: the brightest merged value is M(1, 0) = 0.4.
  const LcdPanel lcd;
  const LcdPanel::Solution from_black = lcd.solve(0.9, 0.0);
  EXPECT_FALSE(from_black.reachable);
  EXPECT_EQ(from_black.v, 1.0);
  // From white the darkest merged value is M(0, 1) = 0.4.
  const LcdPanel::Solution from_white = lcd.solve(0.0, 1.0);
  EXPECT_FALSE(from_white.reachable);
  EXPECT_EQ(from_white.v, 0.0);
  // Exactly at the edge is reachable.
  const LcdPanel::Solution edge = lcd.solve(lcd.merge(1.0, 0.0), 0.0);
  EXPECT_TRUE(edge.reachable);
  EXPECT_NEAR(edge.v, 1.0, 1e-12);
}

TEST(LcdPanel, HeldDriveRoundTripsEvenWhenTheMergeIsNotTheIdentity) {
  // M(v, v) = -0.1 v^2 + v here, so the held drive is not simply x^(1/gamma).
  const Panel panel = parse_panel("lcd:-0.1,0.1,0.5,0,2.2");
  for (int k = 0; k <= 100; ++k) {
    const double x = std::pow(k / 100.0, 2.0) * std::pow(0.9, 2.2);  // M(1, 1)^gamma = 0.9^2.2 is the top
    const double v = panel.drive_from_linear(x, 0);
    EXPECT_NEAR(panel.linear_from_drive(v, 0), x, 1e-13);
  }
  // Defaults: the held drive is x^(1/gamma).
  const Panel lcd = parse_panel("lcd");
  EXPECT_NEAR(lcd.drive_from_linear(0.3, 1), std::pow(0.3, 1.0 / 2.2), 1e-15);
}

// The drive of x_t is the inverse of the emission: an OLED emits x again; an LCD pair driven (v_{t-1}, v_t) merges to
// the average of what the two frames wanted, wherever that is reachable.
TEST(PanelModel, DriveThenEmissionRoundTrips) {
  for (const char* spec : {"vive", "rift", "gamma:2.1,2.2,2.3"}) {
    const Panel oled = parse_panel(spec);
    EXPECT_FALSE(oled.has_history());
    for (int channel = 0; channel < 3; ++channel) {
      for (int i = 0; i <= 64; ++i) {
        const double x = i / 64.0;
        const PanelDriveSample s = oled.drive(x, 0.9, 0.9, channel);  // history is ignored
        EXPECT_TRUE(s.reachable);
        EXPECT_EQ(s.contributed, x);
        EXPECT_NEAR(oled.emitted(s.v, 0.3, channel), x, 1e-14) << spec << " x=" << x;
      }
    }
  }
  for (const char* spec : {"lcd", "lcd:-0.05,0.1,0.5,0.01,2.4"}) {
    const Panel lcd = parse_panel(spec);
    EXPECT_TRUE(lcd.has_history());
    int reachable = 0;
    for (int i = 0; i <= 16; ++i) {
      for (int j = 0; j <= 16; ++j) {
        for (double v_prev : {0.0, 0.3, 0.8, 1.0}) {
          const double x_t = i / 16.0;
          const double x_prev = j / 16.0;
          const PanelDriveSample s = lcd.drive(x_t, x_prev, v_prev, 1);
          ASSERT_GE(s.v, 0.0);
          ASSERT_LE(s.v, 1.0);
          const double pair = lcd.emitted(s.v, v_prev, 1);
          if (s.reachable) {
            ++reachable;
            EXPECT_EQ(s.contributed, x_t);
            EXPECT_NEAR(pair, 0.5 * (x_t + x_prev), 1e-12) << spec << " " << x_t << " " << x_prev << " " << v_prev;
          } else {
            // What the frame really added: the pair averages (x_prev + contributed) / 2.
            EXPECT_NEAR(0.5 * (x_prev + s.contributed), pair, 1e-15);
          }
        }
      }
    }
    EXPECT_GT(reachable, 400) << spec;  // most of the grid is reachable
  }
}

// OLED emission is v^gamma_c with the measured Vive gammas (DESIGN §4), and an LCD pair emits M^gamma with M from
// Eq. 7 worked out by hand.
TEST(PanelModel, EmissionMatchesAnalyticValues) {
  const Panel vive = parse_panel("vive");
  EXPECT_NEAR(vive.emitted(0.25, 0.0, 0), std::exp2(-2 * 2.2912), 1e-16);  // 0.25^2.2912 = 2^-4.5824
  EXPECT_NEAR(vive.emitted(0.25, 0.0, 1), std::exp2(-2 * 2.2520), 1e-16);
  EXPECT_NEAR(vive.emitted(0.25, 0.0, 2), std::exp2(-2 * 2.1940), 1e-16);
  EXPECT_EQ(vive.emitted(1.0, 0.0, 2), 1.0);
  EXPECT_EQ(vive.emitted(0.0, 1.0, 2), 0.0);
  EXPECT_EQ(vive.channel_gammas(), (std::array<double, 3>{2.2912, 2.2520, 2.1940}));

  // Defaults p = (-0.1, 0.2, 0.5, 0): M(0.6, 0.2) = -0.1 (0.36 + 0.04) + 0.2 (0.12) + 0.5 (0.8) = 0.384.
  const Panel lcd = parse_panel("lcd");
  EXPECT_NEAR(lcd.emitted(0.6, 0.2, 0), std::pow(0.384, 2.2), 1e-15);
  EXPECT_EQ(lcd.channel_gammas(), (std::array<double, 3>{2.2, 2.2, 2.2}));
  // p = (-0.05, 0.1, 0.5, 0.01): M(0.3, 0.7) = -0.05 (0.09 + 0.49) + 0.1 (0.21) + 0.5 (1.0) + 0.01 = 0.502.
  const Panel custom = parse_panel("lcd:-0.05,0.1,0.5,0.01,2.4");
  EXPECT_NEAR(custom.emitted(0.3, 0.7, 2), std::pow(0.502, 2.4), 1e-15);
  // Held at one drive: M(v, v) = (2 p1 + p2) v^2 + 2 p3 v + p4 = 0.01 + 0.9 (at v = 0.9, 2 p1 + p2 = 0).
  EXPECT_NEAR(custom.linear_from_drive(0.9, 0), std::pow(0.91, 2.4), 1e-15);

  // Drive after v_prev = 0.2 towards x_t = 0.3, x_prev = 0.1 on the default panel: m = 0.2^(1/2.2) and
  // M(v, 0.2) = -0.1 v^2 + 0.54 v + 0.096, so v is the smaller root of -0.1 v^2 + 0.54 v + (0.096 - m) = 0.
  const double m = std::pow(0.2, 1.0 / 2.2);
  const double v = (0.54 - std::sqrt(0.54 * 0.54 + 0.4 * (0.096 - m))) / 0.2;
  const PanelDriveSample s = lcd.drive(0.3, 0.1, 0.2, 0);
  EXPECT_TRUE(s.reachable);
  EXPECT_NEAR(s.target, m, 1e-15);
  EXPECT_NEAR(s.v, v, 1e-14);
}

TEST(PanelModel, EmissionTableIsTheEmissionOfEveryCode) {
  for (const char* spec : {"rift", "lcd:-0.05,0.1,0.5,0.01,2.4"}) {
    const Panel panel = parse_panel(spec);
    const PanelEmission table(panel, 8);
    for (int code : {0, 1, 77, 254, 255}) {
      for (int previous : {0, 128, 255}) {
        for (int channel = 0; channel < 3; ++channel) {
          EXPECT_EQ(table(static_cast<std::uint16_t>(code), static_cast<std::uint16_t>(previous), channel),
                    panel.emitted(code / 255.0, previous / 255.0, channel));
        }
      }
    }
  }
}

TEST(PanelModel, EmissionOfARowIsTheEmissionOfEachCode) {
  const Panel vive = parse_panel("vive");
  const PanelEmission table(vive, 10);
  std::vector<std::uint16_t> codes(3 * 17);
  for (std::size_t k = 0; k < codes.size(); ++k) codes[k] = static_cast<std::uint16_t>((k * 389) % 1024);
  std::vector<double> light(codes.size());
  table.row(codes, light);
  for (std::size_t k = 0; k < codes.size(); ++k) {
    EXPECT_EQ(light[k], vive.emitted(codes[k] / 1023.0, 0.0, static_cast<int>(k % 3))) << k;
  }
  std::vector<double> shorter(codes.size() - 1);
  EXPECT_THROW(table.row(codes, shorter), std::invalid_argument);
  // With history the light of a code depends on the previous one, which a row of codes alone does not give.
  EXPECT_THROW(PanelEmission(parse_panel("lcd"), 8).row(codes, light), std::logic_error);
}

TEST(PanelJson, RoundTripsEveryKind) {
  for (const char* spec : {"vive", "rift", "generic", "gamma:2.4", "gamma:2.1,2.2,2.3", "lcd",
                           "lcd:-0.05,0.1,0.5,0.01,2.4", "lcd:0,0,0.5,0,1.8"}) {
    const Panel panel = parse_panel(spec);
    const nlohmann::json j = panel;
    EXPECT_EQ(j.at("name"), spec);
    EXPECT_EQ(j.at("kind"), panel.has_history() ? "lcd" : "oled");
    EXPECT_EQ(j.get<Panel>(), panel) << j.dump();
    // Through text too (numbers written to round-trip), and through the ordered flavour the reports use.
    EXPECT_EQ(nlohmann::json::parse(j.dump()).get<Panel>(), panel);
    const nlohmann::ordered_json ordered = panel;
    EXPECT_EQ(nlohmann::ordered_json::parse(ordered.dump()).get<Panel>(), panel);
  }
  EXPECT_EQ(nlohmann::json(parse_panel("vive")).dump(),
            R"({"duty":0.2,"gamma":[2.2912,2.252,2.194],"kind":"oled","name":"vive"})");
}

TEST(PanelJson, RefusesBadJsonWithAClearMessage) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {R"([1, 2])", "expected an object"},
      {R"({"name": "x", "gamma": [2.2, 2.2, 2.2], "duty": 0.2})", "missing \"kind\""},
      {R"({"kind": "crt", "name": "x"})", "\"kind\" must be \"oled\" or \"lcd\""},
      {R"({"kind": "oled", "gamma": [2.2, 2.2, 2.2], "duty": 0.2})", "missing \"name\""},
      {R"({"kind": "oled", "name": 3, "gamma": [2.2, 2.2, 2.2], "duty": 0.2})", "\"name\" must be a string"},
      {R"({"kind": "oled", "name": "x", "gamma": [2.2, 2.2], "duty": 0.2})", "must be 3 numbers"},
      {R"({"kind": "oled", "name": "x", "gamma": [2.2, "a", 2.2], "duty": 0.2})", "must be 3 numbers"},
      {R"({"kind": "oled", "name": "x", "gamma": [2.2, 2.2, 2.2]})", "missing \"duty\""},
      {R"({"kind": "oled", "name": "x", "gamma": [2.2, 9, 2.2], "duty": 0.2})", "OLED gamma 9 is outside"},
      {R"({"kind": "oled", "name": "x", "gamma": [2.2, 2.2, 2.2], "duty": 0})", "OLED duty must be in (0, 1]"},
      {R"({"kind": "lcd", "name": "x", "p1": -0.1, "p2": 0.2, "p3": 0.5, "gamma": 2.2})", "missing \"p4\""},
      {R"({"kind": "lcd", "name": "x", "p1": -0.1, "p2": 0.2, "p3": "0.5", "p4": 0, "gamma": 2.2})",
       "\"p3\" must be a number"},
      {R"({"kind": "lcd", "name": "x", "p1": -1, "p2": 0, "p3": 0.5, "p4": 0, "gamma": 2.2})",
       "must be increasing in v_t"},
  };
  for (const auto& [text, fragment] : cases) {
    try {
      (void)nlohmann::json::parse(text).get<Panel>();
      ADD_FAILURE() << "accepted " << text;
    } catch (const std::invalid_argument& e) {
      const std::string message = e.what();
      EXPECT_EQ(message.rfind("panel JSON: ", 0), 0u) << message;
      EXPECT_NE(message.find(fragment), std::string::npos) << text << " -> " << message;
    }
  }
}

}  // namespace
}  // namespace trm
