#pragma once
// A crude MANO-structured hand made of capsules (one per finger bone) and an
// ellipsoidal palm: MANO's kinematic tree and joint order, rigid skinning, a 4-direction
// shape space and an identity pose PCA basis. It exists so that synthetic captures,
// tests and benchmarks run without any model file; real data uses the open hand
// (models/open_hand_*.npz) or MANO. About 1150 vertices and 2100 faces, like MANO.
//
// Layout as MANO: fingers along -x, back of the hand +y, thumb towards +z (right hand;
// the left hand mirrors x). The 16 joints are extra vertices that no face uses, so the
// joint regressor is exact (one-hot). Fingertip vertices are the far poles of the last
// capsules. Betas: 0 overall scale (+10 % per unit), 1 length along the fingers,
// 2 thickness, 3 width; the rest are zero.

#include "hand/hand_model.h"

namespace handlabel {

HandModel MakeCapsuleHand(HandSide side);

}  // namespace handlabel
