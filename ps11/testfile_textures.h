// The .ps11test model's textures and samplers as the library's: a parsed [texture N] section as
// a ps11::Texture, a [sampler N] section as a ps11::SamplerState. The test model's side of the
// hand-over (the runner, `ps11 eval`, tests and benchmarks use it); the library's public headers
// never include the model.
#pragma once

#include <optional>
#include <string>

#include "ps11/testfile.h"
#include "ps11/texture.h"
#include "ps11/texture_sampler.h"

namespace ps11 {

// Builds a texture from a parsed [texture N] section: texel words in the format's natural
// packing (docs/test-format.md) or float tuples, `fill`, and `levels 0` (generate the whole chain
// from level 0). On failure returns nullopt and sets `error`; never allocates more than
// kMaxResourceBytes. Signed channels decode as `decode` says (the hardware class's rule).
std::optional<Texture> textureFromDesc(const TextureDesc& desc, SignedDecode decode, std::string& error);

// The state a [sampler N] section describes (D3D9 defaults where it is silent).
SamplerState samplerStateFromDesc(const SamplerDesc& desc);

}  // namespace ps11
