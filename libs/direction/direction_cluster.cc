#include "direction/direction_cluster.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>

#include "core/check.h"
#include "direction/ground.h"
#include "direction/mean_shift.h"
#include "geometry/angles.h"

namespace jvl::direction {
namespace {

constexpr double kDeg = M_PI / 180.0;

// A VP that passed the forward filter.
struct Candidate {
  int vp = 0;       // Row in the input.
  size_t pose = 0;  // Row in the prior.
  Eigen::Vector3d d = Eigen::Vector3d::Zero();
};

// A set of candidates (rows of `cands`) with its centre direction.
struct Group {
  std::vector<int> members;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double std_deg = 0;
  int level1 = 0;
};

// Normalised mean of the members' directions and the RMS angle to it.
void UpdateCentre(const std::vector<Candidate>& cands, Group* g) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int m : g->members) sum += cands[m].d;
  g->centre = sum.normalized();
  double sq = 0;
  for (int m : g->members) sq += std::pow(AngleDeg(cands[m].d, g->centre), 2);
  g->std_deg = g->members.empty() ? 0 : std::sqrt(sq / g->members.size());
}

// How the ground headings of a cluster's members turn along the path: the least-squares line
// heading(s) (heading relative to the centre, s the travelled distance at the member's frame).
struct HeadingTurn {
  double rate_deg_per_100m = 0;  // |slope|.
  double sweep_deg = 0;          // |slope| times the cluster's path length.
};
HeadingTurn HeadingTurnAlongPath(const std::vector<Candidate>& cands,
                                 const std::vector<double>& path, const GroundFrame& ground,
                                 const Group& g) {
  const Eigen::Vector2d c = ground.Project(g.centre).normalized();
  double n = 0, ms = 0, mh = 0;
  std::vector<std::pair<double, double>> sh;
  for (int m : g.members) {
    const Eigen::Vector2d d = ground.Project(cands[m].d);
    const double h = std::atan2(c.x() * d.y() - c.y() * d.x(), c.dot(d)) / kDeg;
    const double s = path[cands[m].pose];
    sh.push_back({s, h});
    n += 1, ms += s, mh += h;
  }
  HeadingTurn out;
  if (n < 2) return out;
  ms /= n, mh /= n;
  double sss = 0, ssh = 0, lo = sh.front().first, hi = lo;
  for (const auto& [s, h] : sh) {
    sss += (s - ms) * (s - ms);
    ssh += (s - ms) * (h - mh);
    lo = std::min(lo, s), hi = std::max(hi, s);
  }
  if (sss <= 1e-12) return out;
  const double slope = std::abs(ssh / sss);
  out.rate_deg_per_100m = 100 * slope;
  out.sweep_deg = slope * (hi - lo);
  return out;
}

// A bend: the headings turn by more than max_sweep_deg, at more than max_turn_rate. The rate
// tells a bend (tens of degrees per 100 m) from the prior's own yaw drift on a long straight
// (below 1 deg per 100 m for the lidar-n1 preset), which adds up over a kilometre but is what
// the direction prior is there to correct.
bool IsBend(const HeadingTurn& t, const DirectionClusterOptions& o) {
  return t.sweep_deg > o.max_sweep_deg && t.rate_deg_per_100m > o.max_turn_rate_deg_per_100m;
}

// Step 1 and Alg. 2 lines 2-8: world directions and the forward filter.
std::vector<Candidate> ForwardFilter(const std::vector<VpObservation>& vps, const Trajectory& prior,
                                     const PinholeCamera& camera, const GroundFrame& ground,
                                     const DirectionClusterOptions& o, DirectionClusterStats* st) {
  const std::vector<Eigen::Vector2d> fd = ForwardDirections(prior, ground, o.forward_baseline_m);
  const double cos_max = std::cos(o.forward_max_angle_deg * kDeg);
  std::vector<Candidate> out;
  for (size_t i = 0; i < vps.size(); ++i) {
    const VpObservation& vp = vps[i];
    const auto pose = prior.IndexOf(vp.frame);
    if (!pose) {
      ++st->missing_prior;
      continue;
    }
    if (o.use_forward_flag && !vp.is_forward) continue;
    Eigen::Vector3d ray = vp.direction_cam;
    if (!ray.allFinite() || ray.norm() < 1e-12) ray = camera.Unproject(vp.uv);
    if (!ray.allFinite()) continue;
    // d = R_wc K^-1 v / |R_wc K^-1 v| (Sec. 4.3).
    const Eigen::Vector3d d = (prior.world_from_cam[*pose].rotation() * ray).normalized();
    const Eigen::Vector2d g = ground.Project(d);
    if (g.norm() < o.min_ground_component) continue;
    if (g.normalized().dot(fd[*pose]) < cos_max) continue;
    out.push_back({int(i), *pose, d});
  }
  return out;
}

// Alg. 2 lines 9-25: first-level mean-shift, per-cluster std and slope, subsets by slope, keep
// clusters with std <= Th_delta and size >= Th_n. Returned in subset order, by size within one.
std::vector<Group> FirstLevel(const std::vector<Candidate>& cands, const GroundFrame& ground,
                              const DirectionClusterOptions& o, DirectionClusterStats* st) {
  std::vector<Eigen::Vector3d> dirs;
  for (const auto& c : cands) dirs.push_back(c.d);
  MeanShiftOptions ms;
  ms.bandwidth = o.bandwidth1_deg * kDeg;
  const MeanShiftResult r = MeanShiftSphere(dirs, ms);
  st->level1_clusters = int(r.modes.size());
  std::vector<Group> groups(r.modes.size());
  for (size_t i = 0; i < cands.size(); ++i) {
    const int l = r.labels[i];
    if (AngleDeg(cands[i].d, r.modes[l]) <= o.max_member_angle_deg)
      groups[l].members.push_back(int(i));
  }
  std::vector<double> slope(groups.size());
  for (size_t k = 0; k < groups.size(); ++k) {
    groups[k].level1 = int(k);
    if (!groups[k].members.empty()) UpdateCentre(cands, &groups[k]);
    slope[k] = SlopeDeg(ground, groups[k].centre);
  }
  std::vector<int> order(groups.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return slope[a] < slope[b]; });
  std::vector<Group> kept;
  for (size_t begin = 0; begin < order.size();) {
    size_t end = begin + 1;
    while (end < order.size() && slope[order[end]] - slope[order[end - 1]] <= o.slope_subset_deg)
      ++end;
    std::vector<int> subset(order.begin() + begin, order.begin() + end);
    std::stable_sort(subset.begin(), subset.end(), [&](int a, int b) {
      return groups[a].members.size() > groups[b].members.size();
    });
    for (int k : subset) {
      if (groups[k].std_deg <= o.max_std_deg && int(groups[k].members.size()) >= o.min_size)
        kept.push_back(groups[k]);
    }
    begin = end;
  }
  st->level1_kept = int(kept.size());
  return kept;
}

// Alg. 2 line 26: in every window of Th_l metres of travelled path keep the Th_m clusters with
// the most members there; members in windows where their cluster is not kept are dropped.
std::vector<Group> KeepPerWindow(const std::vector<Candidate>& cands,
                                 const std::vector<double>& path, std::vector<Group> groups,
                                 const DirectionClusterOptions& o) {
  // window -> (cluster -> count)
  std::map<int64_t, std::map<int, int>> counts;
  auto window = [&](int m) { return int64_t(std::floor(path[cands[m].pose] / o.window_length_m)); };
  for (size_t k = 0; k < groups.size(); ++k)
    for (int m : groups[k].members) ++counts[window(m)][int(k)];
  std::map<int64_t, std::vector<int>> winners;
  for (const auto& [w, per_cluster] : counts) {
    std::vector<std::pair<int, int>> ranked(per_cluster.begin(), per_cluster.end());
    // Most members first; ties go to the earlier cluster (larger in its subset).
    std::stable_sort(ranked.begin(), ranked.end(),
                     [](const auto& a, const auto& b) { return a.second > b.second; });
    for (int i = 0; i < std::min<int>(o.clusters_per_window, int(ranked.size())); ++i)
      winners[w].push_back(ranked[i].first);
  }
  std::vector<Group> out;
  for (size_t k = 0; k < groups.size(); ++k) {
    Group g = groups[k];
    g.members.clear();
    for (int m : groups[k].members) {
      const auto& win = winners[window(m)];
      if (std::find(win.begin(), win.end(), int(k)) != win.end()) g.members.push_back(m);
    }
    if (int(g.members.size()) >= o.min_size) out.push_back(g);
  }
  return out;
}

// Root of a label in a union-find forest.
int Find(std::vector<int>& parent, int a) {
  while (parent[a] != a) a = parent[a] = parent[parent[a]];
  return a;
}

// Alg. 2 lines 27-33: second-level mean-shift on the ground positions of each cluster's frames.
// A uniformly sampled straight road has a flat kernel density (many stationary points), so
// mean-shift alone cuts it into pieces about 2 * truncation * bandwidth2 long; sub-clusters
// that follow each other along the path with a gap below link_gap are joined again, and only
// spatially separate runs (the same road direction met again elsewhere) stay apart.
std::vector<Group> SecondLevel(const std::vector<Candidate>& cands, const Trajectory& prior,
                               const GroundFrame& ground, const std::vector<Group>& groups,
                               const DirectionClusterOptions& o) {
  MeanShiftOptions ms;
  ms.bandwidth = o.bandwidth2_m;
  std::vector<Group> out;
  for (Group g : groups) {
    std::stable_sort(g.members.begin(), g.members.end(),
                     [&](int a, int b) { return cands[a].pose < cands[b].pose; });
    std::vector<Eigen::Vector2d> pts;
    for (int m : g.members)
      pts.push_back(ground.Project(prior.world_from_cam[cands[m].pose].translation()));
    const MeanShiftResult r = MeanShiftPlane(pts, ms);
    std::vector<int> parent(r.modes.size());
    std::iota(parent.begin(), parent.end(), 0);
    for (size_t i = 1; i < pts.size() && o.link_gap_m > 0; ++i) {
      if ((pts[i] - pts[i - 1]).norm() > o.link_gap_m) continue;
      const int a = Find(parent, r.labels[i - 1]), b = Find(parent, r.labels[i]);
      parent[std::max(a, b)] = std::min(a, b);
    }
    std::vector<Group> subs(r.modes.size());
    for (size_t i = 0; i < g.members.size(); ++i)
      subs[Find(parent, r.labels[i])].members.push_back(g.members[i]);
    for (Group& s : subs) {
      s.level1 = g.level1;
      if (int(s.members.size()) >= o.min_size) out.push_back(std::move(s));
    }
  }
  return out;
}

// Sec. 4.3: at most one VP per frame; the one closest to its cluster direction wins (ties: the
// higher score, then the lower VP index). Clusters left below Th_n are dropped.
std::vector<Group> OnePerFrame(const std::vector<Candidate>& cands,
                               const std::vector<VpObservation>& vps, std::vector<Group> groups,
                               int min_size) {
  std::map<int64_t, std::pair<int, int>> best;  // frame -> (group, member)
  auto better = [&](int g, int m, const std::pair<int, int>& cur) {
    const double a = AngleDeg(cands[m].d, groups[g].centre);
    const double b = AngleDeg(cands[cur.second].d, groups[cur.first].centre);
    if (a != b) return a < b;
    const auto& va = vps[cands[m].vp];
    const auto& vb = vps[cands[cur.second].vp];
    if (va.score != vb.score) return va.score > vb.score;
    return va.vp_index < vb.vp_index;
  };
  for (size_t g = 0; g < groups.size(); ++g) {
    UpdateCentre(cands, &groups[g]);
    for (int m : groups[g].members) {
      const int64_t f = vps[cands[m].vp].frame;
      const auto it = best.find(f);
      if (it == best.end() || better(int(g), m, it->second)) best[f] = {int(g), m};
    }
  }
  std::vector<Group> out;
  for (size_t g = 0; g < groups.size(); ++g) {
    Group kept = groups[g];
    kept.members.clear();
    for (int m : groups[g].members)
      if (best[vps[cands[m].vp].frame] == std::make_pair(int(g), m)) kept.members.push_back(m);
    if (int(kept.members.size()) < min_size) continue;
    UpdateCentre(cands, &kept);
    out.push_back(std::move(kept));
  }
  return out;
}

}  // namespace

void DirectionClusterOptions::Check() const {
  JVL_CHECK(up.allFinite(), "direction: --up must be finite");
  JVL_CHECK(
      forward_max_angle_deg > 0 && forward_max_angle_deg <= 180,
      "direction: forward max angle (Th_f) must be in (0, 180] deg, got " << forward_max_angle_deg);
  JVL_CHECK(forward_baseline_m > 0, "direction: forward baseline must be > 0 m");
  JVL_CHECK(min_ground_component >= 0 && min_ground_component < 1,
            "direction: min ground component must be in [0, 1)");
  JVL_CHECK(bandwidth1_deg > 0 && bandwidth1_deg < 45,
            "direction: bandwidth1 must be in (0, 45) deg");
  JVL_CHECK(max_member_angle_deg > 0, "direction: max member angle must be > 0 deg");
  JVL_CHECK(slope_subset_deg >= 0, "direction: slope subset width must be >= 0 deg");
  JVL_CHECK(max_std_deg > 0, "direction: max std (Th_delta) must be > 0 deg");
  JVL_CHECK(max_sweep_deg > 0, "direction: max sweep must be > 0 deg");
  JVL_CHECK(max_turn_rate_deg_per_100m >= 0, "direction: max turn rate must be >= 0 deg/100 m");
  JVL_CHECK(min_size >= 1, "direction: min size (Th_n) must be >= 1");
  JVL_CHECK(clusters_per_window >= 1, "direction: clusters per window (Th_m) must be >= 1");
  JVL_CHECK(window_length_m > 0, "direction: window length (Th_l) must be > 0 m");
  JVL_CHECK(bandwidth2_m > 0, "direction: bandwidth2 must be > 0 m");
  JVL_CHECK(link_gap_m >= 0, "direction: link gap must be >= 0 m");
  JVL_CHECK(v_interval >= 0, "direction: --v-interval must be >= 0, got " << v_interval);
}

std::vector<DirectionAssociation> DownsampleAssociations(
    const std::vector<DirectionAssociation>& associations, int interval) {
  std::map<int, int64_t> last_kept;  // cluster -> frame
  std::vector<DirectionAssociation> out;
  for (const auto& a : associations) {  // Input is in frame order.
    const auto it = last_kept.find(a.cluster);
    if (interval > 0 && it != last_kept.end() && a.frame - it->second < interval) continue;
    last_kept[a.cluster] = a.frame;
    out.push_back(a);
  }
  return out;
}

DirectionClusterResult ClusterDirections(const std::vector<VpObservation>& vps,
                                         const Trajectory& prior, const PinholeCamera& camera,
                                         const DirectionClusterOptions& options) {
  options.Check();
  camera.Check();
  prior.Check("prior");
  JVL_CHECK(!prior.empty(), "direction: the prior trajectory is empty");
  DirectionClusterResult result;
  const GroundFrame ground = MakeGroundFrame(prior, options.up);
  result.up = ground.up;
  result.ground_e1 = ground.e1;
  result.ground_e2 = ground.e2;
  DirectionClusterStats& st = result.stats;
  st.input_vps = int(vps.size());
  const std::vector<Candidate> cands = ForwardFilter(vps, prior, camera, ground, options, &st);
  st.forward_kept = int(cands.size());
  std::vector<Group> groups = FirstLevel(cands, ground, options, &st);
  const std::vector<double> path = PathLengths(prior);
  groups = KeepPerWindow(cands, path, std::move(groups), options);
  st.window_kept = int(groups.size());
  groups = SecondLevel(cands, prior, ground, groups, options);
  groups = OnePerFrame(cands, vps, std::move(groups), options.min_size);
  // Th_delta once more on the final clusters: a first-level cluster passes with the spread of
  // all its members, but one of its second-level pieces can be a gentle bend elsewhere whose VPs
  // sweep through the mode's direction and turn with the road (test
  // BendSweepingThroughAStraightsDirectionIsNoPrior: std 2.1 deg; not a single direction).
  const size_t before_std = groups.size();
  groups.erase(std::remove_if(groups.begin(), groups.end(),
                              [&](const Group& g) { return g.std_deg > options.max_std_deg; }),
               groups.end());
  st.level2_too_wide = int(before_std - groups.size());
  // A bend can also pass Th_delta when it is short: its VPs spread little about their mean but
  // turn steadily with the road. Such a cluster is dropped by the sweep of its headings.
  std::vector<Group> straight;
  std::vector<HeadingTurn> turns;  // Of the kept clusters, for their info.
  for (Group& g : groups) {
    const HeadingTurn turn = HeadingTurnAlongPath(cands, path, ground, g);
    if (IsBend(turn, options)) continue;
    straight.push_back(std::move(g));
    turns.push_back(turn);
  }
  st.level2_turning = int(groups.size() - straight.size());
  groups = std::move(straight);
  st.level2_clusters = int(groups.size());
  // Final ids in order of each cluster's first frame.
  std::vector<std::pair<int64_t, int>> first;
  for (size_t g = 0; g < groups.size(); ++g) {
    int64_t f = vps[cands[groups[g].members.front()].vp].frame;
    for (int m : groups[g].members) f = std::min(f, vps[cands[m].vp].frame);
    first.push_back({f, int(g)});
  }
  std::stable_sort(first.begin(), first.end());
  std::vector<DirectionAssociation> all;
  for (size_t id = 0; id < first.size(); ++id) {
    const Group& g = groups[first[id].second];
    DirectionClusterInfo info;
    info.id = int(id);
    info.direction = g.centre;
    info.std_deg = g.std_deg;
    info.members = int(g.members.size());
    info.level1 = g.level1;
    info.slope_deg = SlopeDeg(ground, g.centre);
    const HeadingTurn& turn = turns[first[id].second];
    info.sweep_deg = turn.sweep_deg;
    info.turn_rate_deg_per_100m = turn.rate_deg_per_100m;
    result.clusters.push_back(info);
    for (int m : g.members) {
      const VpObservation& vp = vps[cands[m].vp];
      all.push_back(
          {vp.frame, vp.vp_index, vp.uv, int(id), cands[m].d, AngleDeg(cands[m].d, g.centre)});
    }
  }
  std::stable_sort(all.begin(), all.end(),
                   [](const auto& a, const auto& b) { return a.frame < b.frame; });
  st.associations_before_interval = int(all.size());
  result.associations = DownsampleAssociations(all, options.v_interval);
  st.associations = int(result.associations.size());
  // Size, frame span and centroid describe the associations that are written.
  std::vector<Eigen::Vector3d> sum(result.clusters.size(), Eigen::Vector3d::Zero());
  for (auto& c : result.clusters) {
    c.first_frame = std::numeric_limits<int64_t>::max();
    c.last_frame = std::numeric_limits<int64_t>::min();
  }
  for (const auto& a : result.associations) {
    DirectionClusterInfo& c = result.clusters[a.cluster];
    ++c.size;
    c.first_frame = std::min(c.first_frame, a.frame);
    c.last_frame = std::max(c.last_frame, a.frame);
    sum[a.cluster] += prior.world_from_cam[*prior.IndexOf(a.frame)].translation();
  }
  for (auto& c : result.clusters) c.centroid = sum[c.id] / std::max(1, c.size);
  return result;
}

}  // namespace jvl::direction
