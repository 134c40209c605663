#include "loop/vocabulary.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgproc.hpp>
#include <random>

#include "core/temp_dir.h"
#include "io/artifact.h"
#include "io/schema_check.h"

namespace jvl::loop {
namespace {

using vision::Descriptor;

// Images of descriptors drawn around `places` random centres (a few bits flipped each), every
// image holding the descriptors of one place.
std::vector<std::vector<Descriptor>> PlaceImages(int places, int per_image, uint32_t seed) {
  std::mt19937 random(seed);
  std::vector<std::vector<Descriptor>> centres(static_cast<size_t>(places));
  for (auto& c : centres) {
    c.resize(40);
    for (Descriptor& d : c)
      for (uint8_t& b : d) b = static_cast<uint8_t>(random() & 0xff);
  }
  std::vector<std::vector<Descriptor>> images;
  for (int p = 0; p < places; ++p) {
    for (int view = 0; view < 2; ++view) {
      std::vector<Descriptor> image;
      for (int i = 0; i < per_image; ++i) {
        Descriptor d = centres[static_cast<size_t>(p)][static_cast<size_t>(i) % 40];
        for (int flip = 0; flip < 3; ++flip) {
          const uint32_t bit = random() % 256;
          d[bit / 8] ^= static_cast<uint8_t>(1u << (bit % 8));
        }
        image.push_back(d);
      }
      images.push_back(image);
    }
  }
  return images;
}

TEST(Vocabulary, RejectsBadOptions) {
  VocabularyOptions o;
  o.branching = 1;
  EXPECT_THROW(o.Check(), std::exception);
  o = VocabularyOptions{};
  o.depth = 0;
  EXPECT_THROW(o.Check(), std::exception);
  EXPECT_THROW(Vocabulary::Train({{}, {}}, VocabularyOptions{}, 1), std::exception);
}

TEST(Vocabulary, TreeShapeAndDeterminism) {
  const auto images = PlaceImages(12, 200, 7);
  VocabularyOptions o;
  o.branching = 4;
  o.depth = 3;
  const Vocabulary a = Vocabulary::Train(images, o, 1);
  const Vocabulary b = Vocabulary::Train(images, o, 2);  // Thread count changes nothing.
  EXPECT_LE(a.num_words(), 64);
  EXPECT_GT(a.num_words(), 16);
  EXPECT_EQ(a.training_images(), 24);
  EXPECT_EQ(a.training_descriptors(), 24 * 200);
  ASSERT_EQ(a.num_words(), b.num_words());
  for (const auto& image : images) {
    for (const Descriptor& d : image) {
      // A descriptor's word is stable: the same every time and with every vocabulary trained
      // the same way.
      ASSERT_EQ(a.Word(d), a.Word(d));
      ASSERT_EQ(a.Word(d), b.Word(d));
      ASSERT_GE(a.Word(d), 0);
      ASSERT_LT(a.Word(d), a.num_words());
    }
  }
  for (int w = 0; w < a.num_words(); ++w) EXPECT_EQ(a.WordWeight(w), b.WordWeight(w));
}

TEST(Vocabulary, ScoresAreSymmetricOneOnTheSameImageAndSeparatePlaces) {
  const auto images = PlaceImages(12, 200, 11);
  VocabularyOptions o;
  o.branching = 6;
  o.depth = 3;
  const Vocabulary v = Vocabulary::Train(images, o, 2);
  std::vector<BowVector> bows;
  for (const auto& image : images) bows.push_back(v.Transform(image));
  double same_place = 1, other_place = 0;
  for (size_t i = 0; i < bows.size(); ++i) {
    double sum = 0;
    for (const auto& [w, weight] : bows[i]) sum += weight;
    EXPECT_NEAR(sum, 1.0, 1e-12);
    EXPECT_NEAR(Vocabulary::Score(bows[i], bows[i]), 1.0, 1e-12);
    for (size_t j = 0; j < bows.size(); ++j) {
      const double s = Vocabulary::Score(bows[i], bows[j]);
      EXPECT_EQ(s, Vocabulary::Score(bows[j], bows[i]));
      EXPECT_GE(s, 0.0);
      EXPECT_LE(s, 1.0);
      if (i == j) continue;
      if (i / 2 == j / 2)
        same_place = std::min(same_place, s);  // Two views of one place.
      else
        other_place = std::max(other_place, s);
    }
  }
  EXPECT_GT(same_place, other_place);
  EXPECT_EQ(Vocabulary::Score({}, bows[0]), 0.0);
  EXPECT_EQ(Vocabulary::Score({{1, 0.5}, {3, 0.5}}, {{2, 0.5}, {4, 0.5}}), 0.0);
}

TEST(Vocabulary, OrbImagesOfTheSamePlaceScoreHigherThanOthers) {
  // Textured images (smoothed noise); a view of an image shifted by 12 pixels against an image
  // of other noise.
  auto texture = [](uint64_t seed) {
    cv::Mat noise(240, 320, CV_8U);
    cv::RNG rng(seed);
    rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
    cv::GaussianBlur(noise, noise, cv::Size(5, 5), 1.5);
    cv::normalize(noise, noise, 0, 255, cv::NORM_MINMAX);
    return noise;
  };
  vision::OrbOptions orb;
  orb.num_features = 500;
  std::vector<std::vector<Descriptor>> training;
  for (uint64_t s = 100; s < 120; ++s)
    training.push_back(vision::ExtractOrb(texture(s), orb).descriptors);
  VocabularyOptions o;  // 4096 words for 10000 training descriptors.
  const Vocabulary v = Vocabulary::Train(training, o, 2);
  const cv::Mat a = texture(1), other = texture(2);
  const cv::Mat shifted = a(cv::Rect(12, 0, 308, 240)).clone();
  const BowVector ba = v.Transform(vision::ExtractOrb(a, orb).descriptors);
  const BowVector bs = v.Transform(vision::ExtractOrb(shifted, orb).descriptors);
  const BowVector bo = v.Transform(vision::ExtractOrb(other, orb).descriptors);
  EXPECT_GT(Vocabulary::Score(ba, bs), 2 * Vocabulary::Score(ba, bo) + 0.1);
}

TEST(Vocabulary, SavesAndLoadsTheSameTree) {
  const auto images = PlaceImages(6, 100, 3);
  VocabularyOptions o;
  o.branching = 5;
  o.depth = 2;
  const Vocabulary v = Vocabulary::Train(images, o, 1);
  const TempDir tmp("jvl_vocabulary");
  const std::filesystem::path path = tmp.path() / "vocabulary.h5";
  v.Save(path.string(), io::Provenance{});
  const Vocabulary w = Vocabulary::Load(path.string());
  EXPECT_EQ(w.num_words(), v.num_words());
  EXPECT_EQ(w.num_nodes(), v.num_nodes());
  EXPECT_EQ(w.branching(), 5);
  EXPECT_EQ(w.depth(), 2);
  EXPECT_EQ(w.training_images(), v.training_images());
  for (const auto& image : images)
    for (const Descriptor& d : image) ASSERT_EQ(w.Word(d), v.Word(d));
  for (int i = 0; i < v.num_words(); ++i) EXPECT_EQ(w.WordWeight(i), v.WordWeight(i));

  // A tree whose children are not listed breadth first is refused with the file's name.
  {
    io::H5Writer writer(path.string(), "vocabulary", 1);
    writer.WriteArray("nodes/center", std::vector<uint8_t>(3 * 32, 0), {3, 32});
    writer.WriteArray("nodes/first_child", std::vector<int32_t>{2, -1, -1});
    writer.WriteArray("nodes/child_count", std::vector<int32_t>{2, 0, 0});
    writer.WriteArray("words/weight", std::vector<double>{1, 1});
    writer.WriteJson("vocabulary", {{"branching", 2}, {"depth", 1}});
    writer.Commit(io::Provenance{});
  }
  try {
    Vocabulary::Load(path.string());
    ADD_FAILURE() << "a bad tree was accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
  }
  std::filesystem::remove(path);
}

TEST(Vocabulary, ShippedVocabularyLoadsAndMatchesItsSchema) {
  const std::string path = std::string(JVL_SOURCE_DIR) + "/data/vocabulary/orb_sim_k8_l4.h5";
  const Vocabulary v = Vocabulary::Load(path);
  EXPECT_EQ(v.branching(), 8);
  EXPECT_EQ(v.depth(), 4);
  EXPECT_EQ(v.num_words(), 4096);
  EXPECT_EQ(v.training_images(), 160);
  EXPECT_TRUE(io::CheckH5AgainstSchema(
                  path, std::string(JVL_SOURCE_DIR) + "/schemas/vocabulary.schema.json")
                  .empty());
}

}  // namespace
}  // namespace jvl::loop
