// Scene files: arbitrary bytes as a scene JSON (with unit strings such as "800MPa"), parsed into a
// Scene, plus the same bytes as a command-line override "key=value". Either mufric::Error (or a JSON
// parse error, reported as an Error by read_scene_json) or a scene with finite, positive sizes.
#include <cmath>
#include <cstdlib>

#include "common/error.hpp"
#include "fuzz_support.hpp"
#include "micro/scene/scene.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string& path = mufric::fuzz::write_input(data, size, ".json");
  try {
    const mufric::scene::Scene scene = mufric::scene::load_scene(path, {});
    if (!(scene.contact.penalty > 0) || !std::isfinite(scene.contact.penalty)) std::abort();
  } catch (const mufric::Error&) {
  }
  // The same bytes as an override of the default scene, as `--set` passes them.
  try {
    const std::string assignment(reinterpret_cast<const char*>(data), size);
    mufric::scene::scene_with_overrides(mufric::scene::default_scene_json(), {assignment}, "fuzz");
  } catch (const mufric::Error&) {
  }
  return 0;
}
