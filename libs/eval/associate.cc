#include "eval/associate.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/check.h"

namespace jvl::eval {

AssociationMode ParseAssociationMode(const std::string& name) {
  if (name == "frame") return AssociationMode::kFrame;
  if (name == "timestamp") return AssociationMode::kTimestamp;
  JVL_THROW("unknown association '" << name << "' (expected frame or timestamp)");
}

std::string ToString(AssociationMode mode) {
  return mode == AssociationMode::kFrame ? "frame" : "timestamp";
}

void AssociationOptions::Check() const {
  JVL_CHECK(std::isfinite(max_dt) && max_dt >= 0, "max_dt must be >= 0 (got " << max_dt << ")");
}

namespace {

// est row -> gt row (or -1) by nearest timestamp.
std::vector<long> NearestByTime(const PoseSeries& gt, const PoseSeries& est, double max_dt,
                                const std::string& est_name) {
  JVL_CHECK(gt.has_timestamps(), "timestamp association: the ground truth has no timestamps");
  JVL_CHECK(est.has_timestamps(), "timestamp association: " << est_name << " has no timestamps");
  std::vector<long> match(est.size(), -1);
  std::vector<double> best(gt.size(), std::numeric_limits<double>::infinity());
  std::vector<long> owner(gt.size(), -1);
  for (size_t e = 0; e < est.size(); ++e) {
    const double t = est.timestamps[e];
    const auto it = std::lower_bound(gt.timestamps.begin(), gt.timestamps.end(), t);
    long g = -1;
    double dt = std::numeric_limits<double>::infinity();
    for (auto cand : {it - 1, it}) {  // The neighbours on both sides of t.
      if (cand < gt.timestamps.begin() || cand >= gt.timestamps.end()) continue;
      const double d = std::abs(*cand - t);
      if (d < dt) dt = d, g = static_cast<long>(cand - gt.timestamps.begin());
    }
    if (g < 0 || dt > max_dt) continue;
    if (dt < best[g]) {  // Ties keep the earlier estimate.
      if (owner[g] >= 0) match[owner[g]] = -1;
      best[g] = dt, owner[g] = static_cast<long>(e), match[e] = g;
    }
  }
  return match;
}

}  // namespace

Association Associate(const PoseSeries& gt, const PoseSeries& est,
                      const AssociationOptions& options, const std::string& est_name) {
  options.Check();
  std::vector<long> match(est.size(), -1);
  if (options.mode == AssociationMode::kFrame) {
    for (size_t e = 0; e < est.size(); ++e) {
      if (const auto g = gt.IndexOf(est.frames[e])) match[e] = static_cast<long>(*g);
    }
  } else {
    match = NearestByTime(gt, est, options.max_dt, est_name);
  }
  Association a;
  for (size_t e = 0; e < est.size(); ++e) {
    if (match[e] < 0) {
      a.est_unmatched_frames.push_back(est.frames[e]);
      continue;
    }
    a.gt_row.push_back(static_cast<size_t>(match[e]));
    a.est_row.push_back(e);
  }
  JVL_CHECK(!a.gt_row.empty(), est_name << ": no pose matches the ground truth (association by "
                                        << ToString(options.mode) << "; est frames "
                                        << (est.empty() ? 0 : est.frames.front()) << ".."
                                        << (est.empty() ? 0 : est.frames.back()) << ", gt frames "
                                        << (gt.empty() ? 0 : gt.frames.front()) << ".."
                                        << (gt.empty() ? 0 : gt.frames.back()) << ")");
  // Timestamps increase in both series, so the nearest-neighbour map is monotonic.
  for (size_t k = 1; k < a.gt_row.size(); ++k) {
    JVL_CHECK(a.gt_row[k] > a.gt_row[k - 1], est_name << ": association is not monotonic");
  }
  size_t k = 0;
  for (size_t g = a.gt_row.front(); g <= a.gt_row.back(); ++g) {
    if (a.gt_row[k] == g) {
      ++k;
    } else {
      a.gt_missing_frames.push_back(gt.frames[g]);
    }
  }
  return a;
}

}  // namespace jvl::eval
