// A vocabulary of binary visual words for place recognition: the bag-of-binary-words scheme of
// Galvez-Lopez and Tardos (IEEE T-RO 2012) that ORB-SLAM2 uses for loop detection.
//
// * The words are the leaves of a tree built by hierarchical k-majority clustering of ORB
//   descriptors (k-means with the Hamming distance, k-means++ seeding, a cluster's centre the
//   bitwise majority of its members), `branching` children per node and `depth` levels.
// * An image's descriptors become a bag-of-words vector: each descriptor descends the tree to its
//   word; the weight of a word is its term frequency in the image times its inverse document
//   frequency over the training images (log(N / N_w)); the vector is L1-normalised.
// * Two vectors are compared with the L1 score s = 1 - |a - b|_1 / 2 = sum_w min(a_w, b_w):
//   symmetric, 1 for the same image, 0 when they share no word.
// The tree and weights are stored in a "vocabulary" artifact (schemas/vocabulary.schema.json).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "io/artifact.h"
#include "vision/orb_features.h"

namespace jvl::loop {

// Sparse bag-of-words vector: (word, weight) sorted by word, weights summing to 1.
using BowVector = std::vector<std::pair<int32_t, double>>;

struct VocabularyOptions {
  int branching = 8;    // k: children per node.
  int depth = 4;        // Levels below the root: up to branching^depth words.
  int iterations = 10;  // k-majority iterations per node (fewer when the assignment settles).
  uint64_t seed = 1;    // k-means++ seeding.
  void Check() const;
};

class Vocabulary {
 public:
  // Trains on the descriptors of each training image (one entry per image).
  static Vocabulary Train(const std::vector<std::vector<vision::Descriptor>>& images,
                          const VocabularyOptions& options, int threads);
  // Reads a vocabulary artifact (throws naming the file on a bad layout).
  static Vocabulary Load(const std::string& path);
  void Save(const std::string& path, const io::Provenance& provenance) const;

  int num_words() const { return static_cast<int>(word_weight_.size()); }
  int num_nodes() const { return static_cast<int>(centers_.size()); }
  int branching() const { return branching_; }
  int depth() const { return depth_; }
  int64_t training_images() const { return training_images_; }
  int64_t training_descriptors() const { return training_descriptors_; }
  // Inverse document frequency of a word.
  double WordWeight(int32_t word) const { return word_weight_[static_cast<size_t>(word)]; }

  // The word of a descriptor (descends the tree choosing the nearest centre; ties: lower index).
  // node_at_level (optional): the node `level` levels below the root on the way (the leaf if the
  // word lies higher): descriptors sharing it are the candidates for matching (a direct index).
  int32_t Word(const vision::Descriptor& d, int level = 0, int32_t* node_at_level = nullptr) const;
  // The TF-IDF vector of an image's descriptors (empty for none).
  BowVector Transform(const std::vector<vision::Descriptor>& descriptors) const;
  // L1 score in [0, 1].
  static double Score(const BowVector& a, const BowVector& b);

 private:
  int branching_ = 0, depth_ = 0;
  int64_t training_images_ = 0, training_descriptors_ = 0;
  // Nodes breadth first, node 0 the root; the children of a node are contiguous.
  std::vector<vision::Descriptor> centers_;
  std::vector<int32_t> first_child_;   // -1 for a leaf.
  std::vector<int32_t> child_count_;   // 0 for a leaf.
  std::vector<int32_t> word_of_node_;  // Word id of a leaf, -1 for an inner node.
  std::vector<double> word_weight_;    // IDF per word.
  void CheckLayout(const std::string& source) const;
};

}  // namespace jvl::loop
