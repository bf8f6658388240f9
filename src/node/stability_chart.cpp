#include "stability_chart.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace hunting_monitor {

namespace {

geometry_msgs::Point at(double v_kmh, double amp_m) {
  geometry_msgs::Point p;
  p.x = StabilityChart::kX0 + StabilityChart::kPerKmh * std::min(std::max(v_kmh, 0.0), StabilityChart::kSpeedMax);
  p.y = 0.0;
  p.z = StabilityChart::kPerM * std::min(std::max(amp_m, 0.0), StabilityChart::kAmpMax);
  return p;
}

visualization_msgs::Marker base(const std::string& frame, const ros::Time& now, const char* ns, int id, int type,
                                float r, float g, float b) {
  visualization_msgs::Marker m;
  m.header.frame_id = frame;
  m.header.stamp = now;
  m.ns = ns;
  m.id = id;
  m.type = type;
  m.action = visualization_msgs::Marker::ADD;
  m.pose.orientation.w = 1.0;
  m.scale.x = m.scale.y = m.scale.z = 0.03;
  m.color.r = r;
  m.color.g = g;
  m.color.b = b;
  m.color.a = 1.0;
  return m;
}

visualization_msgs::Marker label(const std::string& frame, const ros::Time& now, const char* ns, int id,
                                 const geometry_msgs::Point& p, const std::string& text, double size) {
  visualization_msgs::Marker m =
      base(frame, now, ns, id, visualization_msgs::Marker::TEXT_VIEW_FACING, 1.0f, 1.0f, 1.0f);
  m.pose.position = p;
  m.scale.z = size;
  m.text = text;
  return m;
}

}  // namespace

const float* levelColour(hm_level level) {
  static const float colours[5][3] = {{0.5f, 0.5f, 0.5f}, {0.1f, 0.8f, 0.1f}, {0.9f, 0.9f, 0.1f},
                                      {1.0f, 0.55f, 0.0f}, {0.9f, 0.1f, 0.1f}};
  const int i = static_cast<int>(level);
  return colours[i >= 0 && i < 5 ? i : 0];
}

std::string hopfMarginWords(double margin_kmh) {
  char text[48];
  std::snprintf(text, sizeof text, "%.1f km/h %s", std::fabs(margin_kmh), margin_kmh >= 0.0 ? "below" : "ABOVE");
  return text;
}

void StabilityChart::drawFamily(visualization_msgs::MarkerArray* arr, double conicity, hm_table table,
                                const ros::Time& now) {
  visualization_msgs::Marker clear;
  clear.action = visualization_msgs::Marker::DELETEALL;  // the previous family's labels and folds
  arr->markers.push_back(clear);
  // axes with ticks every 100 km/h and 4 mm
  visualization_msgs::Marker axes = base(frame_id_, now, "chart_axes", 0, visualization_msgs::Marker::LINE_LIST, 0.8f,
                                         0.8f, 0.8f);
  axes.scale.x = 0.015;
  auto segment = [&axes](geometry_msgs::Point a, geometry_msgs::Point b) {
    axes.points.push_back(a);
    axes.points.push_back(b);
  };
  segment(at(0, 0), at(kSpeedMax, 0));
  segment(at(0, 0), at(0, kAmpMax));
  int id = 0;
  for (int v = 100; v <= kSpeedMax; v += 100) {
    geometry_msgs::Point p = at(v, 0), q = p;
    q.z -= 0.08;
    segment(p, q);
    q.z -= 0.15;
    arr->markers.push_back(label(frame_id_, now, "chart_ticks", id++, q, std::to_string(v), 0.14));
  }
  for (int mm = 4; mm <= 16; mm += 4) {
    geometry_msgs::Point p = at(0, mm * 1e-3), q = p;
    q.x -= 0.08;
    segment(p, q);
    q.x -= 0.25;
    arr->markers.push_back(label(frame_id_, now, "chart_ticks", id++, q, std::to_string(mm), 0.14));
  }
  arr->markers.push_back(axes);
  geometry_msgs::Point title_v = at(kSpeedMax / 2, 0), title_a = at(0, kAmpMax);
  title_v.z -= 0.5;
  title_a.z += 0.3;
  arr->markers.push_back(label(frame_id_, now, "chart_ticks", id++, title_v, "V [km/h]", 0.18));
  arr->markers.push_back(label(frame_id_, now, "chart_ticks", id++, title_a, "max|y| [mm]", 0.18));
  // the family: stable cycles thick green, unstable thin red; the Hopf point and folds marked and labelled
  std::vector<hm_family_point> pts(4096);
  size_t n = 0;
  int exact = 0;
  if (hm_table_family(table, conicity, pts.data(), pts.size(), &n, &exact) != HM_OK || n < 2) return;
  n = std::min(n, pts.size());
  visualization_msgs::Marker stable =
      base(frame_id_, now, "chart_family", 0, visualization_msgs::Marker::LINE_LIST, 0.1f, 0.8f, 0.1f);
  visualization_msgs::Marker unstable =
      base(frame_id_, now, "chart_family", 1, visualization_msgs::Marker::LINE_LIST, 0.9f, 0.15f, 0.15f);
  stable.scale.x = 0.05;
  unstable.scale.x = 0.02;
  for (size_t k = 0; k + 1 < n; ++k) {
    visualization_msgs::Marker& m = pts[k].stable ? stable : unstable;
    m.points.push_back(at(pts[k].speed_kmh, pts[k].amp_m));
    m.points.push_back(at(pts[k + 1].speed_kmh, pts[k + 1].amp_m));
  }
  if (!stable.points.empty()) arr->markers.push_back(stable);
  if (!unstable.points.empty()) arr->markers.push_back(unstable);
  visualization_msgs::Marker marks =
      base(frame_id_, now, "chart_family", 2, visualization_msgs::Marker::SPHERE_LIST, 1.0f, 1.0f, 1.0f);
  marks.scale.x = marks.scale.y = marks.scale.z = 0.1;
  char text[96];
  std::snprintf(text, sizeof text, "Hopf %.1f", pts[0].speed_kmh);
  marks.points.push_back(at(pts[0].speed_kmh, 0.0));
  geometry_msgs::Point lp = marks.points.back();
  lp.z -= 0.35;
  arr->markers.push_back(label(frame_id_, now, "chart_labels", 0, lp, text, 0.14));
  int fold_id = 1;
  for (size_t k = 0; k < n; ++k) {
    if (!pts[k].fold) continue;
    marks.points.push_back(at(pts[k].speed_kmh, pts[k].amp_m));
    geometry_msgs::Point p = marks.points.back();
    p.x += 0.95;  // the label (about 1.7 m wide, centred) to the right of its mark
    std::snprintf(text, sizeof text, "LPC %.1f km/h, %.1f mm", pts[k].speed_kmh, 1e3 * pts[k].amp_m);
    arr->markers.push_back(label(frame_id_, now, "chart_labels", fold_id++, p, text, 0.12));
  }
  arr->markers.push_back(marks);
  geometry_msgs::Point tp = at(kSpeedMax / 2, kAmpMax);
  tp.z += 0.45;
  std::snprintf(text, sizeof text, "cycles at conicity %.4f (%s)", conicity, exact ? "exact family" : "interpolated");
  arr->markers.push_back(label(frame_id_, now, "chart_labels", fold_id, tp, text, 0.18));
}

visualization_msgs::MarkerArray StabilityChart::update(const hm_monitor_status& st, hm_table table,
                                                       const ros::Time& now) {
  visualization_msgs::MarkerArray arr;
  const hm_assessment& s = st.assessment;
  const hm_estimate& e = st.estimate;
  if (!s.boundaries_valid) return arr;
  const size_t size = hm_table_size(table, nullptr, nullptr);
  if (s.conicity != drawn_conicity_ || size != drawn_table_size_ || std::fabs(now.toSec() - drawn_at_) > 5.0) {
    drawFamily(&arr, s.conicity, table, now);
    drawn_conicity_ = s.conicity;
    drawn_table_size_ = size;
    drawn_at_ = now.toSec();
  }
  // the operating point in the level's colour, the last 30 s behind it, the margins
  const float* c = levelColour(s.level);
  const double t = now.toSec(), amp = e.oscillation_valid ? e.amplitude_displacement_m : 0.0;
  trail_.push_back({t, e.speed_kmh, amp});
  while (!trail_.empty() && (trail_.front().t < t - 30.0 || trail_.front().t > t)) trail_.pop_front();
  visualization_msgs::Marker trail =
      base(frame_id_, now, "chart_now", 1, visualization_msgs::Marker::LINE_STRIP, 0.6f, 0.6f, 0.6f);
  trail.scale.x = 0.02;
  for (const Past& p : trail_) trail.points.push_back(at(p.v, p.amp));
  if (trail.points.size() >= 2) arr.markers.push_back(trail);
  visualization_msgs::Marker point =
      base(frame_id_, now, "chart_now", 0, visualization_msgs::Marker::SPHERE, c[0], c[1], c[2]);
  point.scale.x = point.scale.y = point.scale.z = 0.2;
  point.pose.position = at(e.speed_kmh, amp);
  arr.markers.push_back(point);
  // in words, not signs (hopfMarginWords)
  char text[200];
  const double ml = s.margin_lowest_cycle_kmh;
  char lowest[96];
  if (ml >= 0.0)
    std::snprintf(lowest, sizeof lowest, "%.1f km/h below the lowest cycle speed", ml);
  else
    std::snprintf(lowest, sizeof lowest, "bistable band (%.1f km/h above the lowest cycle speed)", -ml);
  std::snprintf(text, sizeof text, "%s  V %.1f km/h  %s the Hopf speed\n%s", hm_level_name(s.level), e.speed_kmh,
                hopfMarginWords(s.margin_hopf_kmh).c_str(), lowest);
  geometry_msgs::Point tp = at(kSpeedMax / 2, kAmpMax);
  tp.z += 0.95;  // two lines above the family's title
  arr.markers.push_back(label(frame_id_, now, "chart_now", 2, tp, text, 0.18));
  drawInterval(&arr, s, now);
  return arr;
}

void StabilityChart::drawInterval(visualization_msgs::MarkerArray* arr, const hm_assessment& s, const ros::Time& now) {
  // the Hopf interval the level uses, a band on the speed axis in the level's colour
  const float* c = levelColour(s.level);
  visualization_msgs::Marker band =
      base(frame_id_, now, "chart_now", 3, visualization_msgs::Marker::CUBE, c[0], c[1], c[2]);
  const geometry_msgs::Point lo = at(s.hopf_low_kmh, 0.0), hi = at(s.hopf_high_kmh, 0.0);
  band.pose.position.x = 0.5 * (lo.x + hi.x);
  band.pose.position.z = -0.04;  // just below the axis: the family's Hopf point stays visible on it
  band.scale.x = std::max(hi.x - lo.x, 0.01);
  band.scale.y = 0.02;
  band.scale.z = 0.08;
  band.color.a = 0.6;
  arr->markers.push_back(band);
  // while a latched ALARM holds: the speed below which its calm counts, a vertical line, labelled
  visualization_msgs::Marker release =
      base(frame_id_, now, "chart_now", 4, visualization_msgs::Marker::LINE_LIST, 0.2f, 0.8f, 1.0f);
  geometry_msgs::Point top = at(s.hold_release_below_kmh, kAmpMax);
  top.z += 0.1;
  visualization_msgs::Marker text = label(frame_id_, now, "chart_now", 5, top, "", 0.14);
  if (s.latched && std::isfinite(s.hold_release_below_kmh)) {
    release.scale.x = 0.02;
    release.points.push_back(at(s.hold_release_below_kmh, 0.0));
    release.points.push_back(at(s.hold_release_below_kmh, kAmpMax));
    char words[96];
    std::snprintf(words, sizeof words, "release below %.1f km/h", s.hold_release_below_kmh);
    text.text = words;
  } else {
    release.action = text.action = visualization_msgs::Marker::DELETE;
  }
  arr->markers.push_back(release);
  arr->markers.push_back(text);
}

}  // namespace hunting_monitor
