#pragma once
// Push-out's later rounds (solvers/contact/push_out_rounds.h): a guard against two bodies of
// infinite mass pushing the central body c in opposite directions (not in the thesis). The
// narrow phase reports each pair's direction of least penetration. For a box standing on another
// static box, or a wall hovering just over the ground, that direction can be the box's bottom
// face: a small body lying at the wall's foot that pokes further into the wall sideways than it
// sticks up out of the ground is pushed down by the wall and up by the ground, and no push
// satisfies both (random drops 40, 222, 412: a needle and small hulls 50-67 % of their size deep
// without this guard). Where the directions of two static bodies oppose (cosine below -1/2), the
// static box among them that the body leaves most cheaply through a face within 120 degrees of
// every direction opposing it (escapeThroughBoxFace) contributes that push instead of its
// points, until no two oppose or no box can give way. Frozen bodies are left out (only static
// bodies count): counting them, and avoiding every other static's direction rather than the
// opposing ones', sends bodies through a wall's far face, over a metre. The outers of each body
// of infinite mass are consecutive in `outers`. A wall standing on a static half-space does not
// show its bottom face (its collision box reaches down through the ground,
// solvers/collision/grounded_box.h), so this guard matters for statics that stand on no
// half-space.
#include <vector>

#include "solvers/contact/push_out.h"
#include "systems/contact_workspace.h"

namespace monolith {

// Rewrites the outer bodies of one central-body solve (`outers`, with `outerIndex` the body of
// each; `fraction` of the distance is pushed on this level iteration). Pushes shorter than
// `tolerance` are not taken.
template <int d>
void escapeOpposedStatics(const std::vector<ContactBody<d>>& bodies, const ContactBody<d>& central, double fraction,
                          double tolerance, std::vector<solvers::contact::PushOutOuter<d>>& outers,
                          std::vector<int>& outerIndex);

}  // namespace monolith
