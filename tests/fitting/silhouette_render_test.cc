// ProjectedMeshIoU (filled projected triangles in a window) against core's rasteriser
// (RenderHandMask, exact rays) and MaskIoU on whole images.

#include "fitting/silhouette_render.h"

#include <gtest/gtest.h>

#include "tests/fitting/fitting_scene.h"
#include "tests/fitting/tube_hand.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

TEST(SilhouetteRenderTest, ProjectedMeshIoUMatchesTheRasteriser) {
  const HandModel model = testing::MakeTubeHand();
  const testing::SceneFrame frame = testing::RandomSceneFrame(model, testing::TestRng());
  int views = 0;
  for (const KeypointView& view : frame.views) {
    const PixelRays rays(view.camera.camera);
    const MaskImage rendered =
        RenderHandMask(frame.mesh.vertices, model.faces, view.camera, rays);
    if (rendered.cast<int>().sum() < 100) continue;  // hand (nearly) out of view
    ++views;
    // The mesh against its own rendering: the fill covers the rasteriser's pixels.
    EXPECT_GT(ProjectedMeshIoU(frame.mesh.vertices, model.faces, view.camera, rendered),
              0.99);
    // Against a mask shifted by 3 px, with a band of pixels ignored: as MaskIoU.
    MaskImage shifted = MaskImage::Zero(rendered.rows(), rendered.cols());
    shifted.rightCols(rendered.cols() - 3) = rendered.leftCols(rendered.cols() - 3);
    MaskImage ignore = MaskImage::Zero(rendered.rows(), rendered.cols());
    ignore.middleRows(rendered.rows() / 2, 20).setConstant(255);
    EXPECT_NEAR(
        ProjectedMeshIoU(frame.mesh.vertices, model.faces, view.camera, shifted, &ignore),
        MaskIoU(rendered, shifted, &ignore), 0.01);
  }
  EXPECT_GT(views, 4);
}

}  // namespace
}  // namespace handlabel
