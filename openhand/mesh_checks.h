#pragma once
// Quality measurements of closed triangle meshes (the open hand's checks and
// `handlabel model info`): topology, orientation, volume, self-intersections, and
// faces that turn over when a hand is posed.

#include <Eigen/Core>
#include <vector>

#include "hand/hand_lbs.h"
#include "hand/hand_model.h"

namespace handlabel {

struct MeshTopology {
  int num_vertices = 0, num_faces = 0, num_edges = 0;
  int boundary_edges = 0;        // edges with one face (0 for a closed mesh)
  int nonmanifold_edges = 0;     // edges with more than two faces
  int misoriented_edges = 0;     // edges whose two faces run it the same way
  int nonmanifold_vertices = 0;  // vertices whose faces form more than one fan
  int unused_vertices = 0;
  int degenerate_faces = 0;      // repeated vertex ids
  int components = 0;            // connected components (by shared edges)
  int euler_characteristic = 0;  // V - E + F (2 for a closed sphere-like surface)
  // Closed, 2-manifold, consistently oriented, one component, genus 0.
  bool IsClosedManifold() const;
};

MeshTopology AnalyzeMeshTopology(
    int num_vertices,
    const Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>& faces);

// Signed volume (divergence theorem); positive when faces are counter-clockwise seen
// from outside.
double SignedVolume(const Points3d& vertices,
                    const Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>& faces);

// Pairs of faces that share no vertex but intersect (edge of one crosses the other).
std::vector<std::pair<int, int>> SelfIntersectingFacePairs(
    const Points3d& vertices,
    const Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>& faces);
int CountSelfIntersections(
    const Points3d& vertices,
    const Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>& faces);

// Faces of a posed hand whose normal points against the rest normal carried by the
// face's dominant joint rotation (the joint with the largest summed weight): a measure
// of skinning collapse. Returns the fraction of faces.
double InvertedFaceFraction(const HandModel& model, const HandParams& params);

// Global rotation of every joint for a pose (chain of Rodrigues rotations).
std::vector<Eigen::Matrix3d> GlobalJointRotations(const HandModel& model,
                                                  const HandParams& params);

}  // namespace handlabel
