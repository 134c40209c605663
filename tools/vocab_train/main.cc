// vocab_train: trains the visual loop detector's vocabulary of binary words (libs/loop/
// vocabulary.h) on the ORB features of every K-th image of one or more sequences, and writes it
// as a vocabulary artifact for loop_detect --vocabulary.
#include <spdlog/spdlog.h>

#include <string>
#include <vector>

#include "app/tool.h"
#include "core/check.h"
#include "core/progress.h"
#include "core/threads.h"
#include "io/dataset.h"
#include "loop/vocabulary.h"
#include "vision/orb_features.h"

int main(int argc, char** argv) {
  using namespace jvl;
  app::Tool tool("vocab_train",
                 "Trains the vocabulary of binary visual words of loop_detect's visual detector: "
                 "ORB features (as loop_detect extracts them) of every K-th image of the "
                 "sequences given, clustered into a tree of branching^depth words by "
                 "hierarchical k-majority, with inverse document frequencies over those images.");
  std::vector<std::string> datasets;
  std::string frames = ":", output;
  io::DatasetOptions dataset_options;
  int every = 10, camera = 0;
  loop::VocabularyOptions options;
  vision::OrbOptions orb;
  CLI::App& cli = tool.cli();
  cli.add_option("--dataset,-d", datasets, "Sequence folders to train on (repeat the option)")
      ->required();
  tool.AddDatasetOptions(&dataset_options);
  cli.add_option("--frames", frames, "Frame range A:B of every sequence (B exclusive)")
      ->capture_default_str();
  cli.add_option("--every", every, "Use every K-th image")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cli.add_option("--camera", camera, "Camera whose images are used")
      ->capture_default_str()
      ->check(CLI::Range(0, 3));
  cli.add_option("--branching", options.branching, "Children per node (k)")->capture_default_str();
  cli.add_option("--depth", options.depth, "Levels of the tree (up to k^depth words)")
      ->capture_default_str();
  cli.add_option("--iterations", options.iterations, "k-majority iterations per node")
      ->capture_default_str();
  cli.add_option("--seed", options.seed, "Seed of the k-means++ seeding")->capture_default_str();
  cli.add_option("--features", orb.num_features, "ORB features per image")->capture_default_str();
  tool.OutputFile(
      cli.add_option("-o,--output", output, "Output vocabulary artifact (.h5)")->required());
  return tool.Run(argc, argv, [&] {
    options.Check();
    orb.Check();
    struct Image {
      const io::Dataset* dataset;
      int64_t frame;
    };
    std::vector<std::unique_ptr<io::Dataset>> opened;
    std::vector<Image> images;
    for (const std::string& dir : datasets) {
      opened.push_back(io::OpenDataset(dir, dataset_options, ParseFrameRange(frames)));
      opened.back()->CheckCamera(camera);
      // Inputs, but no sequence id: a vocabulary serves every sequence.
      for (const std::string& f : opened.back()->KeyFiles()) tool.AddInput(f, false);
      if (!opened.back()->calibration_file().empty())
        tool.AddInput(opened.back()->calibration_file(), false);
      const auto& f = opened.back()->frames();
      for (size_t i = 0; i < f.size(); i += static_cast<size_t>(every))
        images.push_back({opened.back().get(), f[i]});
    }
    JVL_CHECK(!images.empty(), "no images to train on");
    Progress progress("images", static_cast<int64_t>(images.size()), !tool.quiet());
    std::vector<std::vector<vision::Descriptor>> descriptors(images.size());
    ParallelFor(static_cast<int64_t>(images.size()), tool.threads(), [&](int64_t i) {
      const Image& image = images[static_cast<size_t>(i)];
      descriptors[static_cast<size_t>(i)] =
          vision::ExtractOrb(image.dataset->LoadImage(image.frame, camera), orb).descriptors;
      progress.Tick();
    });
    const loop::Vocabulary vocabulary =
        loop::Vocabulary::Train(descriptors, options, tool.threads());
    vocabulary.Save(output, tool.MakeProvenance());
    spdlog::info(
        "vocab_train: {} images, {} descriptors -> {} words ({} nodes, k {}, depth {}) -> {}",
        vocabulary.training_images(), vocabulary.training_descriptors(), vocabulary.num_words(),
        vocabulary.num_nodes(), vocabulary.branching(), vocabulary.depth(), output);
  });
}
