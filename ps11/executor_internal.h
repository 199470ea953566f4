// Executor internals shared by its stages: the per-run register file in structure-of-arrays
// lanes and the kernels of each family (executor_arith.cpp, executor_texture.cpp). The decoded op
// list, the profile and the register slot layout they run over are public
// (ps11/decoded_program.h). Not part of the public API.
#pragma once

#include <array>
#include <cstdint>

#include "ps11/decoded_program.h"
#include "ps11/executor.h"

namespace ps11::exec {

// Lanes processed at once inside run(): a span is cut into chunks of this size so the working
// set (registers + scratch) stays in L1.
constexpr int kChunk = 128;

// Register storage of one chunk. Only one of the int / float banks is used per profile.
template <class T>
struct Bank {
    alignas(64) T reg[kNumSlots][4][kChunk];
    alignas(64) T hold[4][kChunk];  // held result of a co-issued pair's first member
};

struct RunState {
    int n = 0;  // lanes in this chunk
    int offset = 0;  // lane offset of the chunk inside the span
    const PixelInputs* in = nullptr;
    Sampler* sampler = nullptr;
    Bank<int32_t> bi;
    Bank<float> bf;
    alignas(64) int32_t k[3][4][kChunk];   // fx: fetched sources as k (value k/(2G))
    alignas(64) float x[3][4][kChunk];     // float: fetched sources
    alignas(64) float pad[2][kChunk];      // texm3x2pad / texm3x3pad dot products
    alignas(64) float zeros[kChunk];
    alignas(64) uint8_t killed[kChunk];
    alignas(64) float depth[kChunk];
    bool depthWritten = false;
    // Set by the fx8 fast path around tex/texld: sampleInto then leaves the ±M clamp of the
    // texels to the caller, which clamps while converting to its int16 registers.
    bool deferTexelClamp = false;
};

// Arithmetic instruction (mov … bem, not nop) into out (the destination or the hold buffer).
void execArithFx(const Profile& p, const DOp& op, RunState& st, int32_t (*out)[kChunk]);
void execArithFloat(const Profile& p, const DOp& op, RunState& st, float (*out)[kChunk]);
// Texture-address instruction.
void execTexture(const Profile& p, const DOp& op, RunState& st);

// Pointer to TC[set][comp] lanes of the chunk (zeros when absent).
const float* texcoordLanes(const RunState& st, int set, int comp);

}  // namespace ps11::exec
