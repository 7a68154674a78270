#pragma once
// A right-hand rest skeleton in the MANO layout (metres): the 16 native joints, then the
// 5 fingertips (thumb, index, middle, ring, pinky). Fingers along -x, back of the hand
// +y, thumb +z, as MANO and the open hand. The capsule hand (hand/capsule_hand.h)
// and the tests' stick hand are built on it.

namespace handlabel {

inline constexpr double kRestSkeleton[21][3] = {{0, 0, 0},  // wrist
                                                {-0.09, 0, 0.025},
                                                {-0.13, 0, 0.025},
                                                {-0.155, 0, 0.025},  // index
                                                {-0.092, 0.002, 0.004},
                                                {-0.137, -0.003, 0.005},
                                                {-0.165, -0.006, 0.006},  // middle
                                                {-0.08, 0.0, -0.035},
                                                {-0.11, -0.004, -0.04},
                                                {-0.128, -0.007, -0.043},  // pinky
                                                {-0.088, 0.001, -0.016},
                                                {-0.13, -0.003, -0.019},
                                                {-0.157, -0.006, -0.021},  // ring
                                                {-0.02, -0.01, 0.025},
                                                {-0.045, -0.015, 0.05},
                                                {-0.065, -0.018, 0.065},   // thumb
                                                {-0.085, -0.02, 0.075},    // thumb tip
                                                {-0.175, 0, 0.025},        // index tip
                                                {-0.186, -0.009, 0.007},   // middle tip
                                                {-0.177, -0.009, -0.022},  // ring tip
                                                {-0.144, -0.01, -0.045}};  // pinky tip

}  // namespace handlabel
