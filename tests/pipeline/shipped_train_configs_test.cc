// The committed training configs are the shipped network's recipe
// (docs/model-card-poem-small.md): each loads, and the values the model card states are
// the ones the configs hold, so an edit that breaks the recipe fails here.

#include <gtest/gtest.h>

#include <string>

#include "pipeline/train_config.h"

namespace handlabel {
namespace {

TrainConfig LoadShipped(const std::string& name) {
  return LoadTrainConfig(std::string(HANDLABEL_SOURCE_DIR) + "/jobs/" + name);
}

TEST(ShippedTrainConfigs, MainRunIsEmptyHandsOnSeed1) {
  const TrainConfig c = LoadShipped("train_poem_small.yaml");
  EXPECT_EQ(c.network_name, "small");
  EXPECT_FALSE(c.synth.scene.objects);
  EXPECT_EQ(c.synth.seed, 1u);
  EXPECT_FALSE(c.network.mask_head);
}

TEST(ShippedTrainConfigs, ContinuationHoldsObjectsInHalfTheFramesOnNewScenes) {
  const TrainConfig main = LoadShipped("train_poem_small.yaml");
  const TrainConfig c = LoadShipped("train_poem_small_objects.yaml");
  EXPECT_TRUE(c.synth.scene.objects);
  EXPECT_DOUBLE_EQ(c.synth.scene.object_probability, 0.5);
  EXPECT_NE(c.synth.seed, main.synth.seed);  // the main run's scenes are spent
  EXPECT_EQ(c.validation_seed, main.validation_seed);
  EXPECT_EQ(c.trainer.steps, 40000);  // lr 1e-4, x0.1 at 28000
  EXPECT_DOUBLE_EQ(c.trainer.learning_rate, 1e-4);
  EXPECT_DOUBLE_EQ(c.trainer.decay_at * c.trainer.steps, 28000.0);
  // Same network as the main run, so --init-weights takes its average.
  EXPECT_EQ(c.network_name, main.network_name);
  EXPECT_EQ(c.network.mask_head, main.network.mask_head);
  EXPECT_EQ(c.samples.crop_size, main.samples.crop_size);
}

TEST(ShippedTrainConfigs, MaskHeadTrainsAloneOnTheContinuationsScenes) {
  const TrainConfig objects = LoadShipped("train_poem_small_objects.yaml");
  const TrainConfig c = LoadShipped("train_poem_small_masks.yaml");
  EXPECT_TRUE(c.network.mask_head);
  EXPECT_TRUE(c.trainer.mask_head_only);
  EXPECT_EQ(c.synth.seed, objects.synth.seed);
  EXPECT_TRUE(c.synth.scene.objects);
  EXPECT_DOUBLE_EQ(c.synth.scene.object_probability,
                   objects.synth.scene.object_probability);
}

}  // namespace
}  // namespace handlabel
