// `ps11 info`: reports the build and the machine — the ps11 version, the default hardware class,
// the CPU features, the SIMD level in use and the fx8 executor kernels it gives, and the GL
// backend's context (kind, GL_RENDERER,
// GL_VERSION, GL_SHADING_LANGUAGE_VERSION) or why none could be made (docs/gl-backend.md).
#include "tools/cmd_info.h"

#include <iostream>
#include <optional>
#include <string>

#include "ps11/cpu_features.h"
#include "ps11/executor_fast.h"
#include "ps11/hardware.h"
#include "ps11/json_internal.h"
#include "ps11/simd_dispatch.h"
#include "ps11/suggest.h"
#include "ps11/version.h"
#include "tools/cli_util.h"
#ifdef PS11_HAVE_GL
#include "emu/gl/context.h"
#endif

namespace ps11 {

namespace {

constexpr const char* kInfoUsage = "usage: ps11 info [--gl osmesa|egl] [--json]\n";

// The GL part of the report: the context's facts, or the error.
struct GlReport {
    bool ok = false;
    std::string kind, platform, renderer, version, glsl, error;
};

GlReport probeGl(const std::optional<std::string>& kindName) {
    GlReport r;
#ifdef PS11_HAVE_GL
    std::optional<emu::gl::ContextKind> kind;
    if (kindName) kind = emu::gl::parseContextKind(*kindName);
    std::string error;
    std::unique_ptr<emu::gl::Context> ctx = emu::gl::createContext(kind, error);
    if (!ctx) {
        r.error = error;
        return r;
    }
    r.ok = true;
    r.kind = std::string(emu::gl::contextKindName(ctx->kind()));
    r.platform = ctx->platform();
    r.renderer = ctx->renderer();
    r.version = ctx->version();
    r.glsl = ctx->shadingLanguageVersion();
#else
    (void)kindName;
    r.error = "the OpenGL backend is not in this build (configured with PS11_GL=OFF)";
#endif
    return r;
}

}  // namespace

int cmdInfo(const std::vector<std::string>& args) {
    bool json = false;
    std::optional<std::string> gl;
    for (size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        if (a == "--json") {
            json = true;
        } else if (a == "--gl") {
            if (i + 1 >= args.size()) {
                std::cerr << "ps11: info: --gl needs osmesa or egl\n" << kInfoUsage;
                return cli::kUsage;
            }
            gl = args[++i];
            if (*gl != "osmesa" && *gl != "egl") {
                std::cerr << "ps11: info: --gl takes osmesa or egl, not " << quote(*gl)
                          << didYouMean(*gl, {"osmesa", "egl"}) << "\n"
                          << kInfoUsage;
                return cli::kUsage;
            }
        } else if (a == "-h" || a == "--help") {
            std::cout << kInfoUsage;
            return cli::kOk;
        } else {
            std::cerr << "ps11: info: " << cli::unknownOption(a, {"--gl", "--json"}) << "\n" << kInfoUsage;
            return cli::kUsage;
        }
    }
    const HardwareClass& hw = defaultHardware(1);
    const SimdLevel level = simdLevel();
    const exec::FastKernels* kernels = exec::fastKernels(level);
    const char* kernelName = kernels ? kernels->name : "none";
    std::string levelText = simdLevelName(level);
    if (level != bestSimdLevel())
        levelText += std::string(" (forced; this CPU runs ") + simdLevelName(bestSimdLevel()) + ")";
    const CpuFeatures& cpu = cpuFeatures();
    std::string cpuText;
    for (auto [name, has] : {std::pair{"avx2", cpu.avx2}, std::pair{"fma", cpu.fma}, std::pair{"f16c", cpu.f16c},
                             std::pair{"avx512", cpu.avx512}})
        if (has) cpuText += cpuText.empty() ? name : std::string(" ") + name;
    if (cpuText.empty()) cpuText = "none of avx2, fma, f16c, avx512";
    GlReport r = probeGl(gl);
    if (json) {
        json::Json j;
        j["version"] = versionString();
        j["hardware"] = hw.name;
        j["simd_level"] = simdLevelName(level);
        j["executor_kernels"] = kernelName;
        j["cpu"] = {{"avx2", cpu.avx2}, {"fma", cpu.fma}, {"f16c", cpu.f16c}, {"avx512", cpu.avx512}};
        if (r.ok)
            j["gl"] = {{"kind", r.kind},
                       {"platform", r.platform},
                       {"GL_RENDERER", r.renderer},
                       {"GL_VERSION", r.version},
                       {"GL_SHADING_LANGUAGE_VERSION", r.glsl},
                       {"modes", json::Json::array({"exact", "native"})}};
        else
            j["gl"] = {{"error", r.error}};
        std::cout << json::dump(j) << "\n";
    } else {
        std::cout << "ps11 " << versionString() << "\n"
                  << "default hardware: " << hw.name << " (" << hw.kind << ")\n"
                  << "cpu features: " << cpuText << "\n"
                  << "simd level: " << levelText << "\n"
                  << "executor kernels: " << kernelName << "\n";
        if (r.ok) {
            std::cout << "GL context: " << r.kind << " (" << r.platform << ")\n"
                      << "GL_RENDERER: " << r.renderer << "\n"
                      << "GL_VERSION: " << r.version << "\n"
                      << "GL_SHADING_LANGUAGE_VERSION: " << r.glsl << "\n"
                      << "GL renderer modes: exact (bit for bit with the emulator: the cross-check, the default of\n"
                      << "  --backend gl|both) and native (GL's own interpolation, filtering, float arithmetic and\n"
                      << "  blending, surfaces resident: the speed peer; --gl-mode native)\n";
        } else {
            std::cout << "GL context: none (" << r.error << ")\n";
        }
    }
    // Asked for one kind: its failure is the user's error. Otherwise info reports and succeeds.
    if (gl && !r.ok) {
        std::cerr << "ps11: info: " << r.error << "\n";
        return cli::kUserError;
    }
    return cli::kOk;
}

}  // namespace ps11
