// A gtest fixture for the tests that run commands on a workspace: a fresh temporary
// folder with a workspace of arc views over the test world (scene_fixture.h) in dir_/ws.
#pragma once

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "scene/scene_fixture.h"
#include "support/test_support.h"

namespace fvs::testing {

class ArcWorkspaceTest : public ::testing::Test {
 protected:
  ArcWorkspaceTest(int num_views, int width, int height)
      : num_views_(num_views), width_(width), height_(height) {}

  void SetUp() override {
    ws_ = dir_ / "ws";
    views_ = ArcViews(num_views_, width_, height_);
    mesh_ = MakeTestWorldMesh();
    WriteTestWorkspace(ws_, views_, mesh_);
  }

  TempDir dir_;
  std::string ws_;                // the workspace
  std::vector<SceneView> views_;  // its photos' cameras, as written
  TriangleMesh mesh_;             // the world, also its proxy mesh

 private:
  const int num_views_, width_, height_;
};

}  // namespace fvs::testing
