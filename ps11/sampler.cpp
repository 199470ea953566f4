// The null sampler: what a stage without a texture returns, (0, 0, 0, 1) (DX8 docs, DXVK;
// ps1x-spec.md §6.4).
#include "ps11/sampler.h"

namespace ps11 {

void NullSampler::sample(const SampleRequest& req, SampleResult& out) {
    const int32_t one = gridScale(req.precision);
    for (int c = 0; c < 4; ++c) {
        for (int i = 0; i < req.count; ++i) {
            if (out.grid[c]) out.grid[c][i] = c == 3 ? one : 0;
            if (out.value[c]) out.value[c][i] = c == 3 ? 1.0f : 0.0f;
        }
    }
}

}  // namespace ps11
