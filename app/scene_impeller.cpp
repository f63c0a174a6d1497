// Stub: the parametric impeller scene is added by the impeller issue, which replaces this file.
#include "fieldpath/common/errors.h"
#include "scene.h"

namespace fieldpath::app {

void resolveImpeller(Scene& scene) {
  throw common::InputError(scene.file.string() + ": impeller scenes are not available yet");
}

}  // namespace fieldpath::app
