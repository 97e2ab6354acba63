#pragma once
/// @file workspace.hpp
/// The model/data split (Crocoddyl's ActionModel/ActionData,
/// docs/architecture.md#models-and-workspaces): models are immutable and shareable; every caller holds
/// the scratch it writes in a workspace that the model makes (DynamicsWorkspace, StepWorkspace,
/// BeliefWorkspace) and hands back on every call.

#include <cassert>

namespace gpilqg {

/// `workspace` seen as a model's own workspace type W. A workspace belongs to the model that made it;
/// handing one to another kind of model is a programming error (asserted in builds with assertions).
template <class W, class Base>
W& workspace_as(Base& workspace) {
  assert(dynamic_cast<W*>(&workspace) != nullptr && "a workspace made by another model");
  return static_cast<W&>(workspace);
}

}  // namespace gpilqg
