#include "sim/raycaster.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include "core/check.h"

namespace jvl::sim {

// The BVH and the hit test are this project's own scalar code: every CPU that runs the binary
// executes the same IEEE double operations (no kernels chosen by the CPU's vector extensions), so
// the simulator writes the same bytes on every x86-64 machine. A library BVH that picks SSE2,
// AVX2 or AVX-512 kernels at run time moved hit distances by a float ULP from one CPU to another
// and some rays onto a neighbouring triangle.
namespace {

constexpr int kLeafSize = 4;  // At most this many triangles per leaf.
constexpr int kBins = 16;     // SAH bins per axis.
constexpr int kStackSize = 256;

struct Aabb {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity());
  void Grow(const Eigen::Vector3d& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  void Grow(const Aabb& b) {
    lo = lo.cwiseMin(b.lo);
    hi = hi.cwiseMax(b.hi);
  }
  double HalfArea() const {
    if (!(hi.x() >= lo.x())) return 0;
    const Eigen::Vector3d e = hi - lo;
    return e.x() * e.y() + e.y() * e.z() + e.z() * e.x();
  }
};

// Moeller-Trumbore in double precision: the distance along o + t d to the triangle with first
// vertex a and edges e1, e2, or a negative value on a miss (parallel ray or outside).
inline double TriangleHit(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double ax, double ay,
                          double az, double e1x, double e1y, double e1z, double e2x, double e2y,
                          double e2z) {
  const double px = d[1] * e2z - d[2] * e2y;
  const double py = d[2] * e2x - d[0] * e2z;
  const double pz = d[0] * e2y - d[1] * e2x;
  const double det = e1x * px + e1y * py + e1z * pz;
  if (!(std::abs(det) >= 1e-30)) return -1;  // Parallel to the plane.
  const double inv_det = 1.0 / det;
  const double sx = o[0] - ax, sy = o[1] - ay, sz = o[2] - az;
  const double u = (sx * px + sy * py + sz * pz) * inv_det;
  if (u < 0 || u > 1) return -1;
  const double qx = sy * e1z - sz * e1y;
  const double qy = sz * e1x - sx * e1z;
  const double qz = sx * e1y - sy * e1x;
  const double v = (d[0] * qx + d[1] * qy + d[2] * qz) * inv_det;
  if (v < 0 || u + v > 1) return -1;
  return (e2x * qx + e2y * qy + e2z * qz) * inv_det;
}

}  // namespace

struct RayCaster::Impl {
  // Node: box, and either two children (count == 0: the left child at `index`, the right one
  // after it) or a leaf (count triangles from `index` in the reordered arrays).
  // Boxes are floats rounded outwards (32 bytes a node); the tests run in double.
  struct Node {
    float lo[3], hi[3];
    uint32_t index = 0;
    uint32_t count = 0;
  };
  // Reordered triangles: the mesh's float vertices (edges are formed in double at the test).
  struct Triangle {
    float a[3], b[3], c[3];
    uint32_t id;  // Index in mesh.triangles.
  };
  // Four floats (GCC/Clang vector extension: element-wise IEEE operations, SSE on x86-64).
  typedef float F4 __attribute__((vector_size(16)));
  static F4 Splat(float x) { return F4{x, x, x, x}; }
  static F4 Load(const float* p) {
    F4 v;
    std::memcpy(&v, p, sizeof(v));
    return v;
  }
  // The binary tree collapsed to four children a node: per axis the children's box bounds side
  // by side, so one pass of four-lane float arithmetic tests all four boxes. An empty slot has
  // lo = +inf, hi = -inf (never hit); count 0 marks an inner child (index: its Node4).
  struct Node4 {
    float lo[3][4], hi[3][4];
    uint32_t index[4];
    uint16_t count[4];
  };
  // A leaf's triangles (at most four) side by side in double: first vertex and the two edges
  // from it (differences of the mesh's floats, exact in double).
  struct Leaf4 {
    double a[3][4], e1[3][4], e2[3][4];
    uint32_t id[4];  // Index in mesh.triangles.
  };
  std::vector<Node> nodes;          // Binary tree (building only).
  std::vector<Triangle> triangles;  // In leaf order (building only).
  std::vector<Node4> nodes4;
  std::vector<Leaf4> leaves;
  const Mesh* mesh = nullptr;

  void Build(std::vector<uint32_t>& order, const std::vector<Aabb>& boxes,
             const std::vector<Eigen::Vector3d>& centroids);
  void Collapse();
  bool Nearest(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_min, double t_max,
               int32_t hint, double* t, uint32_t* tri) const;
};

void RayCaster::Impl::Build(std::vector<uint32_t>& order, const std::vector<Aabb>& boxes,
                            const std::vector<Eigen::Vector3d>& centroids) {
  struct Task {
    uint32_t node, begin, end;
  };
  std::vector<Task> tasks;
  nodes.emplace_back();
  tasks.push_back({0, 0, static_cast<uint32_t>(order.size())});
  while (!tasks.empty()) {
    const Task task = tasks.back();
    tasks.pop_back();
    Aabb box, cbox;
    for (uint32_t i = task.begin; i < task.end; ++i) {
      box.Grow(boxes[order[i]]);
      cbox.Grow(centroids[order[i]]);
    }
    // Padded outwards so that the box test (double) never drops a triangle on the box's face.
    for (int k = 0; k < 3; ++k) {
      // Covers the float rounding of the ray origin and of the four-lane slab test.
      const double pad = 1e-4 + 1e-5 * std::max(std::abs(box.lo[k]), std::abs(box.hi[k]));
      nodes[task.node].lo[k] =
          std::nextafter(static_cast<float>(box.lo[k] - pad), -std::numeric_limits<float>::max());
      nodes[task.node].hi[k] =
          std::nextafter(static_cast<float>(box.hi[k] + pad), std::numeric_limits<float>::max());
    }
    const uint32_t n = task.end - task.begin;
    // Binned surface area heuristic over the centroids.
    int best_axis = -1, best_bin = 0;
    double best_cost = static_cast<double>(n);  // Cost of a leaf (per triangle test).
    if (n > static_cast<uint32_t>(kLeafSize)) {
      best_cost = std::numeric_limits<double>::infinity();
      for (int axis = 0; axis < 3; ++axis) {
        const double extent = cbox.hi[axis] - cbox.lo[axis];
        if (!(extent > 0)) continue;
        std::array<Aabb, kBins> bin_box;
        std::array<uint32_t, kBins> bin_count{};
        const double scale = kBins / extent;
        for (uint32_t i = task.begin; i < task.end; ++i) {
          const int b = std::min(
              kBins - 1, static_cast<int>((centroids[order[i]][axis] - cbox.lo[axis]) * scale));
          bin_box[b].Grow(boxes[order[i]]);
          ++bin_count[b];
        }
        std::array<double, kBins> right_cost{};
        Aabb acc;
        uint32_t count = 0;
        for (int b = kBins - 1; b > 0; --b) {
          acc.Grow(bin_box[b]);
          count += bin_count[b];
          right_cost[b] = acc.HalfArea() * count;
        }
        acc = Aabb();
        count = 0;
        for (int b = 0; b < kBins - 1; ++b) {
          acc.Grow(bin_box[b]);
          count += bin_count[b];
          const double cost = acc.HalfArea() * count + right_cost[b + 1];
          if (count > 0 && count < n && cost < best_cost) {
            best_cost = cost;
            best_axis = axis;
            best_bin = b;
          }
        }
      }
      // Relative to the parent's area; a split costs one box test (about a triangle test).
      best_cost = best_axis >= 0 ? 1.0 + best_cost / std::max(box.HalfArea(), 1e-300)
                                 : std::numeric_limits<double>::infinity();
    }
    uint32_t mid = task.begin;
    const bool sah_split = best_axis >= 0 && (best_cost < n || n > kLeafSize);
    if (sah_split) {
      const double lo = cbox.lo[best_axis];
      const double scale = kBins / (cbox.hi[best_axis] - lo);
      mid = static_cast<uint32_t>(
          std::stable_partition(order.begin() + task.begin, order.begin() + task.end,
                                [&](uint32_t t) {
                                  return std::min(kBins - 1,
                                                  static_cast<int>((centroids[t][best_axis] - lo) *
                                                                   scale)) <= best_bin;
                                }) -
          order.begin());
    } else if (best_axis < 0 && n > static_cast<uint32_t>(kLeafSize)) {
      // Coincident centroids: halve the range (deterministic) to bound the leaf size.
      mid = task.begin + n / 2;
    }
    if (mid == task.begin || mid == task.end) {
      Node& leaf = nodes[task.node];
      leaf.index = task.begin;
      leaf.count = n;
      continue;
    }
    const uint32_t left = static_cast<uint32_t>(nodes.size()), right = left + 1;
    nodes.emplace_back();
    nodes.emplace_back();
    nodes[task.node].index = left;
    nodes[task.node].count = 0;
    tasks.push_back({right, mid, task.end});
    tasks.push_back({left, task.begin, mid});
  }
}

void RayCaster::Impl::Collapse() {
  const auto half_area = [&](uint32_t n) {
    const Node& nd = nodes[n];
    const double ex = nd.hi[0] - nd.lo[0], ey = nd.hi[1] - nd.lo[1], ez = nd.hi[2] - nd.lo[2];
    return ex * ey + ey * ez + ez * ex;
  };
  struct Task {
    uint32_t binary, node4;
  };
  std::vector<Task> tasks;
  nodes4.emplace_back();
  tasks.push_back({0, 0});
  while (!tasks.empty()) {
    const Task task = tasks.back();
    tasks.pop_back();
    // Open the largest inner child until there are four (a leaf root is its only child).
    std::vector<uint32_t> children;
    if (nodes[task.binary].count > 0) {
      children.push_back(task.binary);
    } else {
      children = {nodes[task.binary].index, nodes[task.binary].index + 1};
    }
    while (children.size() < 4) {
      int open = -1;
      for (size_t c = 0; c < children.size(); ++c) {
        if (nodes[children[c]].count > 0) continue;
        if (open < 0 || half_area(children[c]) > half_area(children[static_cast<size_t>(open)])) {
          open = static_cast<int>(c);
        }
      }
      if (open < 0) break;
      const uint32_t n = children[static_cast<size_t>(open)];
      children[static_cast<size_t>(open)] = nodes[n].index;
      children.insert(children.begin() + open + 1, nodes[n].index + 1);
    }
    Node4 out;
    for (int c = 0; c < 4; ++c) {
      for (int k = 0; k < 3; ++k) {
        out.lo[k][c] = std::numeric_limits<float>::infinity();
        out.hi[k][c] = -std::numeric_limits<float>::infinity();
      }
      out.index[c] = 0;
      out.count[c] = 0;
      if (c >= static_cast<int>(children.size())) continue;
      const Node& nd = nodes[children[static_cast<size_t>(c)]];
      for (int k = 0; k < 3; ++k) {
        out.lo[k][c] = nd.lo[k];
        out.hi[k][c] = nd.hi[k];
      }
      if (nd.count > 0) {
        JVL_CHECK(nd.count <= 4, "BVH leaf of " << nd.count << " triangles");
        Leaf4 leaf{};
        for (uint32_t l = 0; l < nd.count; ++l) {
          const Triangle& tr = triangles[nd.index + l];
          for (int k = 0; k < 3; ++k) {
            leaf.a[k][l] = tr.a[k];
            leaf.e1[k][l] = static_cast<double>(tr.b[k]) - tr.a[k];
            leaf.e2[k][l] = static_cast<double>(tr.c[k]) - tr.a[k];
          }
          leaf.id[l] = tr.id;
        }
        out.index[c] = static_cast<uint32_t>(leaves.size());
        out.count[c] = static_cast<uint16_t>(nd.count);
        leaves.push_back(leaf);
      } else {
        out.index[c] = static_cast<uint32_t>(nodes4.size());
        nodes4.emplace_back();
        tasks.push_back({children[static_cast<size_t>(c)], out.index[c]});
      }
    }
    nodes4[task.node4] = out;
  }
}

bool RayCaster::Impl::Nearest(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_min,
                              double t_max, int32_t hint, double* t_out, uint32_t* tri_out) const {
  // Box tests in float (the padded boxes absorb its rounding), the hit test in double.
  float of[3], inv[3];
  for (int k = 0; k < 3; ++k) {
    of[k] = static_cast<float>(o[k]);
    inv[k] = std::abs(d[k]) < 1e-20 ? std::copysign(1e20f, static_cast<float>(d[k]))
                                    : static_cast<float>(1.0 / d[k]);
  }
  const bool neg[3] = {inv[0] < 0, inv[1] < 0, inv[2] < 0};
  const float t_near = std::nextafter(static_cast<float>(t_min), -1.0f);
  double best = t_max;
  uint32_t best_tri = UINT32_MAX;
  struct Entry {
    uint32_t index;
    uint32_t count;  // 0: a Node4; else the leaf `index` (`count` triangles).
    float t;         // Entry distance into the box.
  };
  Entry stack[kStackSize];
  int top = 0;
  stack[top++] = {0, 0, t_near};
  // Upper end of the box tests: the nearest hit so far, rounded up to a float.
  const auto round_up = [](double t) {
    return std::nextafter(static_cast<float>(t), std::numeric_limits<float>::max());
  };
  float t_far = round_up(best);
  // The hint (usually the neighbouring ray's triangle) first: a close `best` from the start prunes
  // the boxes behind it. The answer does not change: the nearest hit, ties to the lower index.
  if (hint >= 0 && static_cast<size_t>(hint) < mesh->triangles.size()) {
    const auto& v = mesh->triangles[static_cast<size_t>(hint)];
    const Eigen::Vector3f& a = mesh->vertices[v[0]];
    const Eigen::Vector3f& b = mesh->vertices[v[1]];
    const Eigen::Vector3f& c = mesh->vertices[v[2]];
    const double t =
        TriangleHit(o, d, a.x(), a.y(), a.z(), static_cast<double>(b.x()) - a.x(),
                    static_cast<double>(b.y()) - a.y(), static_cast<double>(b.z()) - a.z(),
                    static_cast<double>(c.x()) - a.x(), static_cast<double>(c.y()) - a.y(),
                    static_cast<double>(c.z()) - a.z());
    if (t > t_min && t < best) {
      best = t;
      best_tri = static_cast<uint32_t>(hint);
      t_far = round_up(best);
    }
  }
  Entry next{};
  bool have_next = false;
  while (have_next || top > 0) {
    const Entry e = have_next ? next : stack[--top];
    have_next = false;
    if (e.t > t_far) continue;  // A nearer hit was found after it was pushed.
    if (e.count > 0) {
      const Leaf4& lf = leaves[e.index];
      for (uint32_t l = 0; l < e.count; ++l) {
        const double t =
            TriangleHit(o, d, lf.a[0][l], lf.a[1][l], lf.a[2][l], lf.e1[0][l], lf.e1[1][l],
                        lf.e1[2][l], lf.e2[0][l], lf.e2[1][l], lf.e2[2][l]);
        if (!(t > t_min)) continue;  // A miss, or behind t_min.
        // Nearest wins; an exact tie goes to the lower triangle index, whatever the visit order.
        if (t < best || (t == best && lf.id[l] < best_tri)) {
          best = t;
          best_tri = lf.id[l];
          t_far = round_up(best);
        }
      }
      continue;
    }
    // The four children's boxes at once (element-wise IEEE float operations: the same result
    // whether the compiler vectorises them or not).
    const Node4& nd = nodes4[e.index];
    F4 t0 = Splat(t_near), t1 = Splat(t_far);
    for (int k = 0; k < 3; ++k) {
      const F4 lo = Load(nd.lo[k]), hi = Load(nd.hi[k]);
      const F4 a = ((neg[k] ? hi : lo) - of[k]) * inv[k];
      const F4 b = ((neg[k] ? lo : hi) - of[k]) * inv[k];
      t0 = a > t0 ? a : t0;
      t1 = b < t1 ? b : t1;
    }
    // Children hit, pushed farthest first so that the nearest is taken next.
    Entry hit[4];
    int n = 0;
    for (int c = 0; c < 4; ++c) {
      if (!(t0[c] <= t1[c])) continue;
      Entry h{nd.index[c], nd.count[c], t0[c]};
      int m = n++;
      while (m > 0 && hit[m - 1].t < h.t) {
        hit[m] = hit[m - 1];
        --m;
      }
      hit[m] = h;
    }
    // The nearest is taken straight away, the others wait on the stack.
    JVL_CHECK(top + n <= kStackSize, "BVH deeper than the traversal stack");
    for (int m = 0; m + 1 < n; ++m) stack[top++] = hit[m];
    if (n > 0) {
      next = hit[n - 1];
      have_next = true;
    }
  }
  if (best_tri == UINT32_MAX) return false;
  *t_out = best;
  *tri_out = best_tri;
  return true;
}

RayCaster::RayCaster(const Mesh& mesh) : impl_(std::make_unique<Impl>()) {
  JVL_CHECK(!mesh.triangles.empty(), "scene mesh is empty");
  JVL_CHECK(mesh.triangles.size() < UINT32_MAX, "scene mesh has too many triangles");
  impl_->mesh = &mesh;
  const size_t n = mesh.triangles.size();
  std::vector<Aabb> boxes(n);
  std::vector<Eigen::Vector3d> centroids(n);
  for (size_t i = 0; i < n; ++i) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) {
      const uint32_t vi = mesh.triangles[i][k];
      JVL_CHECK(vi < mesh.vertices.size(), "scene mesh triangle " << i << " has vertex " << vi
                                                                  << " of "
                                                                  << mesh.vertices.size());
      const Eigen::Vector3d p = mesh.vertices[vi].cast<double>();
      boxes[i].Grow(p);
      c += p;
    }
    centroids[i] = c / 3.0;
  }
  std::vector<uint32_t> order(n);
  for (size_t i = 0; i < n; ++i) order[i] = static_cast<uint32_t>(i);
  impl_->nodes.reserve(2 * n / kLeafSize + 1);
  impl_->Build(order, boxes, centroids);
  impl_->triangles.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const auto& tri = mesh.triangles[order[i]];
    Impl::Triangle& t = impl_->triangles[i];
    for (int k = 0; k < 3; ++k) {
      t.a[k] = mesh.vertices[tri[0]][k];
      t.b[k] = mesh.vertices[tri[1]][k];
      t.c[k] = mesh.vertices[tri[2]][k];
    }
    t.id = order[i];
  }
  impl_->Collapse();
  impl_->nodes = {};
  impl_->triangles = {};
}

RayCaster::~RayCaster() = default;

Hit RayCaster::Intersect(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_min,
                         double t_max, int32_t hint) const {
  Hit hit;
  double t = 0;
  uint32_t tri = 0;
  if (!impl_->Nearest(o, d, t_min, t_max, hint, &t, &tri)) return hit;
  const Mesh& mesh = *impl_->mesh;
  const auto& v = mesh.triangles[tri];
  const Eigen::Vector3d a = mesh.vertices[v[0]].cast<double>();
  Eigen::Vector3d normal =
      (mesh.vertices[v[1]].cast<double>() - a).cross(mesh.vertices[v[2]].cast<double>() - a);
  normal.normalize();
  if (normal.dot(d) > 0) normal = -normal;
  hit.t = t;
  hit.face = static_cast<int32_t>(mesh.triangle_face[tri]);
  hit.triangle = static_cast<int32_t>(tri);
  hit.dynamic = -1;
  hit.normal = normal;
  return hit;
}

void RayCaster::Intersect8(const Eigen::Vector3d& o, const Eigen::Vector3d* d, int count,
                           double t_min, double t_max, Hit* hits, int32_t hint) const {
  for (int i = 0; i < count; ++i) {
    hits[i] = Intersect(o, d[i], t_min, t_max, hint);
    if (hits[i].triangle >= 0) hint = hits[i].triangle;
  }
}

void IntersectBoxes(const std::vector<Box>& boxes, const Eigen::Vector3d& o,
                    const Eigen::Vector3d& d, Hit* hit) {
  for (size_t i = 0; i < boxes.size(); ++i) {
    const Box& b = boxes[i];
    if (b.size.x() <= 0) continue;
    // Bounding-sphere rejection before the exact test.
    const Eigen::Vector3d oc = b.center - o;
    const double along = oc.dot(d), r2 = 0.25 * b.size.squaredNorm();
    if (oc.squaredNorm() - along * along > r2 || (along < 0 && oc.squaredNorm() > r2)) continue;
    // Ray in the box frame (rotation about z by yaw), then the slab test.
    const double c = std::cos(b.yaw), s = std::sin(b.yaw);
    const Eigen::Vector3d r = o - b.center;
    const Eigen::Vector3d lo(c * r.x() + s * r.y(), -s * r.x() + c * r.y(), r.z());
    const Eigen::Vector3d ld(c * d.x() + s * d.y(), -s * d.x() + c * d.y(), d.z());
    double t0 = 1e-3, t1 = hit->t;
    int axis = -1;
    bool miss = false;
    for (int k = 0; k < 3 && !miss; ++k) {
      const double h = b.size[k] / 2;
      if (std::abs(ld[k]) < 1e-12) {
        miss = std::abs(lo[k]) > h;
        continue;
      }
      double ta = (-h - lo[k]) / ld[k], tb = (h - lo[k]) / ld[k];
      if (ta > tb) std::swap(ta, tb);
      if (ta > t0) {
        t0 = ta;
        axis = k;
      }
      t1 = std::min(t1, tb);
      miss = t0 > t1;
    }
    if (miss || axis < 0) continue;
    Eigen::Vector3d n_local = Eigen::Vector3d::Zero();
    n_local[axis] = ld[axis] > 0 ? -1.0 : 1.0;
    hit->t = t0;
    hit->face = -1;
    hit->triangle = -1;
    hit->dynamic = static_cast<int32_t>(i);
    hit->normal = Eigen::Vector3d(c * n_local.x() - s * n_local.y(),
                                  s * n_local.x() + c * n_local.y(), n_local.z());
  }
}

}  // namespace jvl::sim
