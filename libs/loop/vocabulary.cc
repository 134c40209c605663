#include "loop/vocabulary.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <memory>

#include "core/check.h"
#include "core/threads.h"

namespace jvl::loop {

constexpr char kVocabularySchema[] = "vocabulary";
constexpr int kVocabularySchemaVersion = 1;

void VocabularyOptions::Check() const {
  JVL_CHECK(branching >= 2 && branching <= 64,
            "vocabulary branching must be in [2, 64], got " << branching);
  JVL_CHECK(depth >= 1 && depth <= 8, "vocabulary depth must be in [1, 8], got " << depth);
  JVL_CHECK(iterations >= 1, "vocabulary iterations must be >= 1, got " << iterations);
}

namespace {

using vision::Descriptor;
using vision::HammingDistance;

// SplitMix64: a small generator whose sequence is the same with every compiler and library.
struct Random {
  uint64_t state;
  uint64_t Next() {
    uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  double Uniform() { return static_cast<double>(Next() >> 11) * 0x1.0p-53; }  // [0, 1)
};

struct TreeNode {
  Descriptor center{};
  std::vector<std::unique_ptr<TreeNode>> children;
};

// Bitwise majority of the members (a bit is set when more than half of them have it).
Descriptor Majority(const std::vector<Descriptor>& all, const std::vector<uint32_t>& members) {
  std::array<int, 256> count{};
  for (const uint32_t m : members) {
    const Descriptor& d = all[m];
    for (int byte = 0; byte < 32; ++byte)
      for (int bit = 0; bit < 8; ++bit) count[8 * byte + bit] += (d[byte] >> bit) & 1;
  }
  Descriptor out{};
  const int n = static_cast<int>(members.size());
  for (int byte = 0; byte < 32; ++byte)
    for (int bit = 0; bit < 8; ++bit)
      if (2 * count[8 * byte + bit] > n) out[byte] |= static_cast<uint8_t>(1u << bit);
  return out;
}

class Trainer {
 public:
  Trainer(const std::vector<Descriptor>& all, const VocabularyOptions& o, int threads)
      : all_(all), o_(o), threads_(threads), random_{o.seed} {}

  // Splits `members` into up to `branching` clusters; recurses below `level` + 1 < depth.
  void Split(const std::vector<uint32_t>& members, int level, TreeNode* node) {
    const size_t k = static_cast<size_t>(o_.branching);
    if (members.size() <= k) {
      // Few enough: each distinct descriptor is a word of its own.
      std::vector<Descriptor> distinct;
      for (const uint32_t m : members) distinct.push_back(all_[m]);
      std::sort(distinct.begin(), distinct.end());
      distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
      for (const Descriptor& d : distinct) {
        node->children.push_back(std::make_unique<TreeNode>());
        node->children.back()->center = d;
      }
      return;
    }
    std::vector<Descriptor> centers = Seed(members, k);
    std::vector<int> assignment(members.size(), -1);
    for (int iteration = 0; iteration < o_.iterations; ++iteration) {
      const bool changed = Assign(members, centers, &assignment);
      if (!changed && iteration > 0) break;
      std::vector<std::vector<uint32_t>> groups(centers.size());
      for (size_t i = 0; i < members.size(); ++i)
        groups[static_cast<size_t>(assignment[i])].push_back(members[i]);
      for (size_t c = 0; c < centers.size(); ++c)
        if (!groups[c].empty()) centers[c] = Majority(all_, groups[c]);
    }
    Assign(members, centers, &assignment);
    std::vector<std::vector<uint32_t>> groups(centers.size());
    for (size_t i = 0; i < members.size(); ++i)
      groups[static_cast<size_t>(assignment[i])].push_back(members[i]);
    for (size_t c = 0; c < centers.size(); ++c) {
      if (groups[c].empty()) continue;  // An empty cluster is dropped.
      node->children.push_back(std::make_unique<TreeNode>());
      TreeNode* child = node->children.back().get();
      child->center = centers[c];
      if (level + 1 < o_.depth && groups[c].size() > 1) Split(groups[c], level + 1, child);
    }
  }

 private:
  // k-means++ seeding: each further centre drawn with probability proportional to the squared
  // distance to the nearest centre so far.
  std::vector<Descriptor> Seed(const std::vector<uint32_t>& members, size_t k) {
    std::vector<Descriptor> centers{all_[members[random_.Next() % members.size()]]};
    std::vector<double> nearest(members.size());
    for (size_t i = 0; i < members.size(); ++i) {
      const double d = HammingDistance(all_[members[i]], centers[0]);
      nearest[i] = d * d;
    }
    while (centers.size() < k) {
      double total = 0;
      for (const double d : nearest) total += d;
      if (total <= 0) break;  // Every member is a centre already.
      const double target = random_.Uniform() * total;
      size_t pick = 0;
      for (double sum = 0; pick + 1 < members.size(); ++pick) {
        sum += nearest[pick];
        if (sum > target) break;
      }
      centers.push_back(all_[members[pick]]);
      for (size_t i = 0; i < members.size(); ++i) {
        const double d = HammingDistance(all_[members[i]], centers.back());
        nearest[i] = std::min(nearest[i], d * d);
      }
    }
    return centers;
  }

  // Nearest centre of every member (ties: the lower index); true if any assignment changed.
  bool Assign(const std::vector<uint32_t>& members, const std::vector<Descriptor>& centers,
              std::vector<int>* assignment) {
    constexpr int64_t kChunk = 4096;
    const int64_t n = static_cast<int64_t>(members.size());
    const int64_t chunks = (n + kChunk - 1) / kChunk;
    std::vector<char> changed(static_cast<size_t>(chunks), 0);
    ParallelFor(chunks, n > kChunk ? threads_ : 1, [&](int64_t c) {
      for (int64_t i = c * kChunk; i < std::min(n, (c + 1) * kChunk); ++i) {
        int best = 0, best_distance = 257;
        for (size_t j = 0; j < centers.size(); ++j) {
          const int d = HammingDistance(all_[members[static_cast<size_t>(i)]], centers[j]);
          if (d < best_distance) best_distance = d, best = static_cast<int>(j);
        }
        int& a = (*assignment)[static_cast<size_t>(i)];
        if (a != best) a = best, changed[static_cast<size_t>(c)] = 1;
      }
    });
    return std::find(changed.begin(), changed.end(), 1) != changed.end();
  }

  const std::vector<Descriptor>& all_;
  const VocabularyOptions& o_;
  int threads_;
  Random random_;
};

}  // namespace

Vocabulary Vocabulary::Train(const std::vector<std::vector<vision::Descriptor>>& images,
                             const VocabularyOptions& options, int threads) {
  options.Check();
  std::vector<Descriptor> all;
  for (const auto& image : images) all.insert(all.end(), image.begin(), image.end());
  JVL_CHECK(!all.empty(),
            "vocabulary training: no descriptors in " << images.size() << " training images");
  JVL_CHECK(all.size() < (1ull << 32), "vocabulary training: too many descriptors");
  TreeNode root;
  std::vector<uint32_t> members(all.size());
  for (size_t i = 0; i < all.size(); ++i) members[i] = static_cast<uint32_t>(i);
  Trainer(all, options, threads).Split(members, 0, &root);

  // Breadth-first layout: the children of each node contiguous, leaves numbered in order.
  Vocabulary v;
  v.branching_ = options.branching;
  v.depth_ = options.depth;
  v.training_images_ = static_cast<int64_t>(images.size());
  v.training_descriptors_ = static_cast<int64_t>(all.size());
  std::deque<const TreeNode*> queue{&root};
  int32_t next = 1, words = 0;
  while (!queue.empty()) {
    const TreeNode* node = queue.front();
    queue.pop_front();
    v.centers_.push_back(node->center);
    const int32_t children = static_cast<int32_t>(node->children.size());
    v.first_child_.push_back(children > 0 ? next : -1);
    v.child_count_.push_back(children);
    v.word_of_node_.push_back(children > 0 ? -1 : words++);
    next += children;
    for (const auto& child : node->children) queue.push_back(child.get());
  }
  // IDF over the training images: log(N / images holding the word); a word no training image
  // lands on (its members moved on the last assignment) counts as the rarest.
  std::vector<int64_t> holding(static_cast<size_t>(words), 0);
  for (const auto& image : images) {
    std::vector<int32_t> seen;
    for (const Descriptor& d : image) seen.push_back(v.Word(d));
    std::sort(seen.begin(), seen.end());
    seen.erase(std::unique(seen.begin(), seen.end()), seen.end());
    for (const int32_t w : seen) ++holding[static_cast<size_t>(w)];
  }
  const double n = static_cast<double>(images.size());
  for (const int64_t h : holding) v.word_weight_.push_back(std::log(n / std::max<int64_t>(h, 1)));
  v.CheckLayout("trained vocabulary");
  return v;
}

void Vocabulary::CheckLayout(const std::string& source) const {
  const size_t n = centers_.size();
  JVL_CHECK(
      n >= 2 && first_child_.size() == n && child_count_.size() == n && word_of_node_.size() == n,
      source << ": the vocabulary's node arrays disagree in length or hold no word");
  int32_t words = 0;
  size_t expected_child = 1;
  for (size_t i = 0; i < n; ++i) {
    if (child_count_[i] == 0) {
      JVL_CHECK(first_child_[i] == -1 && word_of_node_[i] == words,
                source << ": vocabulary node " << i << " is a leaf but not numbered in order");
      ++words;
      continue;
    }
    JVL_CHECK(child_count_[i] > 0 && first_child_[i] == static_cast<int32_t>(expected_child) &&
                  word_of_node_[i] == -1,
              source << ": vocabulary node " << i << " does not list its children breadth first");
    expected_child += static_cast<size_t>(child_count_[i]);
    JVL_CHECK(expected_child <= n,
              source << ": vocabulary node " << i << " has children beyond the last node");
  }
  JVL_CHECK(expected_child == n && child_count_[0] > 0,
            source << ": the vocabulary's tree does not hold every node exactly once");
  JVL_CHECK(word_weight_.size() == static_cast<size_t>(words),
            source << ": " << word_weight_.size() << " word weights for " << words << " words");
  for (const double w : word_weight_)
    JVL_CHECK(std::isfinite(w) && w >= 0, source << ": a word weight is " << w);
}

int32_t Vocabulary::Word(const vision::Descriptor& d, int level, int32_t* node_at_level) const {
  size_t node = 0;
  int at = 0;
  if (node_at_level) *node_at_level = 0;
  while (child_count_[node] > 0) {
    const size_t first = static_cast<size_t>(first_child_[node]);
    size_t best = first;
    int best_distance = 257;
    for (size_t c = first; c < first + static_cast<size_t>(child_count_[node]); ++c) {
      const int distance = HammingDistance(d, centers_[c]);
      if (distance < best_distance) best_distance = distance, best = c;
    }
    node = best;
    if (node_at_level && ++at <= level) *node_at_level = static_cast<int32_t>(node);
  }
  return word_of_node_[node];
}

BowVector Vocabulary::Transform(const std::vector<vision::Descriptor>& descriptors) const {
  std::vector<int32_t> words;
  words.reserve(descriptors.size());
  for (const Descriptor& d : descriptors) words.push_back(Word(d));
  std::sort(words.begin(), words.end());
  BowVector out;
  double total = 0;
  for (size_t i = 0; i < words.size();) {
    size_t j = i;
    while (j < words.size() && words[j] == words[i]) ++j;
    const double weight = static_cast<double>(j - i) * WordWeight(words[i]);
    if (weight > 0) out.emplace_back(words[i], weight), total += weight;
    i = j;
  }
  for (auto& [word, weight] : out) weight /= total;
  return out;
}

double Vocabulary::Score(const BowVector& a, const BowVector& b) {
  double score = 0;
  auto i = a.begin(), j = b.begin();
  while (i != a.end() && j != b.end()) {
    if (i->first < j->first) {
      ++i;
    } else if (j->first < i->first) {
      ++j;
    } else {
      score += std::min(i->second, j->second);
      ++i, ++j;
    }
  }
  return std::min(score, 1.0);
}

void Vocabulary::Save(const std::string& path, const io::Provenance& provenance) const {
  io::H5Writer writer(path, kVocabularySchema, kVocabularySchemaVersion);
  std::vector<uint8_t> centers;
  centers.reserve(32 * centers_.size());
  for (const Descriptor& d : centers_) centers.insert(centers.end(), d.begin(), d.end());
  writer.WriteArray("nodes/center", centers, {static_cast<int64_t>(centers_.size()), 32});
  writer.WriteArray("nodes/first_child", first_child_);
  writer.WriteArray("nodes/child_count", child_count_);
  writer.WriteArray("words/weight", word_weight_);
  writer.WriteJson("vocabulary", {{"branching", branching_},
                                  {"depth", depth_},
                                  {"words", num_words()},
                                  {"training_images", training_images_},
                                  {"training_descriptors", training_descriptors_}});
  writer.Commit(provenance);
}

Vocabulary Vocabulary::Load(const std::string& path) {
  io::H5Reader reader(path, kVocabularySchema, kVocabularySchemaVersion);
  Vocabulary v;
  const std::vector<uint8_t> centers = reader.ReadArray<uint8_t>("nodes/center", 32);
  v.first_child_ = reader.ReadArray<int32_t>("nodes/first_child");
  v.child_count_ = reader.ReadArray<int32_t>("nodes/child_count");
  v.word_weight_ = reader.ReadArray<double>("words/weight");
  v.centers_.resize(centers.size() / 32);
  for (size_t i = 0; i < v.centers_.size(); ++i)
    std::copy_n(centers.begin() + static_cast<std::ptrdiff_t>(32 * i), 32, v.centers_[i].begin());
  int32_t words = 0;
  for (size_t i = 0; i < v.child_count_.size(); ++i)
    v.word_of_node_.push_back(v.child_count_[i] == 0 ? words++ : -1);
  const nlohmann::json info = reader.ReadJson("vocabulary");
  JVL_CHECK(info.is_object() && info.contains("branching") && info.contains("depth"),
            path << ": the 'vocabulary' attribute lacks branching or depth");
  v.branching_ = info["branching"].get<int>();
  v.depth_ = info["depth"].get<int>();
  v.training_images_ = info.value("training_images", int64_t{0});
  v.training_descriptors_ = info.value("training_descriptors", int64_t{0});
  v.CheckLayout(path);
  return v;
}

}  // namespace jvl::loop
