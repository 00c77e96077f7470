#pragma once
// The scene-key reference (`mufric micro keys`, docs/usage.md "Scene keys"): every key the scene
// reader reads, as it reads it — its type, the value an absent key takes, its range or its words —
// gathered by reading the default dry scene, and the same lubricated and under seed 000's protocol,
// and the interface laws' own keys from their registry. Generated from the readers themselves, so
// that the reference cannot drift from the code.
#include <string>

namespace mufric::scene {

// Markdown: a heading per section, a heading per key under it, the laws' table under contact.law.
std::string scene_key_reference();

}  // namespace mufric::scene
