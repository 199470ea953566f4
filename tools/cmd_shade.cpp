#include "tools/cmd_shade.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>

#include "emu/image_file.h"
#include "glare/shade.h"
#include "ps11/assembler.h"
#include "ps11/hardware.h"
#include "ps11/validator.h"
#include "tools/cli_util.h"
#include "runner/gl_backend.h"

namespace ps11 {

namespace {

constexpr const char* kShadeUsage =
    "usage: ps11 shade SHADER.psh [--texN IMG] [--filterN point|linear] [--cN x,y,z,w] [--size WxH]\n"
    "                  [--backend emu|gl] [--gl osmesa|egl] [--gl-mode exact|native] [--hardware H | --precision P]\n"
    "                  [--exposure STOPS] [--no-skip]\n"
    "                  -o OUT.png\n"
    "  N is a texture stage 0..3 (ps_1_4: 0..5) or a constant 0..7; the output size defaults to texture 0's\n"
    "  --no-skip  the emulator draws every tile (no tile skipping; for comparison: the image is the same)\n";

int shadeUsage(const std::string& msg) {
    std::cerr << "ps11 shade: " << msg << "\n" << kShadeUsage;
    return cli::kUsage;
}

// "--tex3" → 3 for prefix "--tex"; -1 when it is not that option.
int indexed(const std::string& arg, const std::string& prefix, int limit) {
    if (arg.rfind(prefix, 0) != 0 || arg.size() != prefix.size() + 1) return -1;
    const int n = arg.back() - '0';
    return n >= 0 && n < limit ? n : -1;
}

}  // namespace

int cmdShade(const std::vector<std::string>& args) {
    bool glNative = false, glModeGiven = false;  // --gl-mode
    std::string shaderPath, out, glKind, backend = "emu";
    std::vector<std::string> textures(6);
    std::vector<emu::D3DTEXTUREFILTERTYPE> filters(6, emu::D3DTEXF_LINEAR);
    glare::ShadeRequest request;
    const HardwareClass* hardware = nullptr;
    std::optional<Precision> precision;
    float exposure = 0;
    bool noSkip = false;  // --no-skip: the emulator draws every tile
    for (size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        std::string v;
        auto value = [&]() {
            if (i + 1 >= args.size()) return false;
            v = args[++i];
            return true;
        };
        int n;
        if (a == "--help" || a == "-h") {
            std::cout << kShadeUsage;
            return cli::kOk;
        } else if ((n = indexed(a, "--tex", 6)) >= 0) {
            if (!value()) return shadeUsage(a + " needs an image file");
            textures[size_t(n)] = v;
        } else if ((n = indexed(a, "--filter", 6)) >= 0) {
            if (!value() || (v != "point" && v != "linear")) return shadeUsage(a + " takes point or linear");
            filters[size_t(n)] = v == "point" ? emu::D3DTEXF_POINT : emu::D3DTEXF_LINEAR;
        } else if ((n = indexed(a, "--c", 8)) >= 0) {
            std::array<float, 4> c{};
            char extra = 0;
            if (!value() || std::sscanf(v.c_str(), "%f,%f,%f,%f%c", &c[0], &c[1], &c[2], &c[3], &extra) != 4 ||
                !std::isfinite(c[0] + c[1] + c[2] + c[3]))
                return shadeUsage(a + " takes four numbers x,y,z,w");
            request.constants.push_back({n, c});
        } else if (a == "--size") {
            uint32_t w = 0, h = 0;
            if (!value() || !cli::parseSize(v, w, h)) return shadeUsage("--size takes " + cli::sizeRule());
            request.width = w, request.height = h;
        } else if (a == "--backend") {
            if (!value() || (v != "emu" && v != "gl")) return shadeUsage("--backend takes emu or gl");
            backend = v;
        } else if (a == "--gl") {
            if (!value() || (v != "osmesa" && v != "egl")) return shadeUsage("--gl takes osmesa or egl");
            glKind = v;
        } else if (a == "--gl-mode") {
            if (!value() || (v != "exact" && v != "native")) return shadeUsage("--gl-mode takes exact or native");
            glNative = v == "native";
            glModeGiven = true;
        } else if (a == "--hardware") {
            if (!value()) return shadeUsage("--hardware needs a class");
            hardware = findHardware(v);
            if (!hardware) return shadeUsage(unknownHardwareMessage(v));
        } else if (a == "--precision") {
            if (!value()) return shadeUsage("--precision needs a profile");
            precision = parsePrecision(v);
            if (!precision) return shadeUsage("unknown precision '" + v + "' (expected fx8, fx12, float or ideal)");
        } else if (a == "--exposure") {
            char* end = nullptr;
            if (!value()) return shadeUsage("--exposure needs a number of stops");
            exposure = std::strtof(v.c_str(), &end);
            if (end == v.c_str() || *end || !std::isfinite(exposure) || std::fabs(exposure) > 64)
                return shadeUsage("--exposure takes stops in -64 .. 64");
        } else if (a == "--no-skip") {
            noSkip = true;
        } else if (a == "-o" || a == "--out") {
            if (!value()) return shadeUsage("-o needs a file name");
            out = v;
        } else if (a.size() > 1 && a[0] == '-') {
            return shadeUsage(cli::unknownOption(a, {"--tex0", "--filter0", "--c0", "--size", "--backend", "--gl", "--gl-mode",
                                                     "--hardware", "--precision", "--exposure", "--no-skip", "-o",
                                                     "--help"}));
        } else if (shaderPath.empty()) {
            shaderPath = a;
        } else {
            return shadeUsage("one shader file, not '" + a + "' as well");
        }
    }
    if (shaderPath.empty()) return shadeUsage("say which shader (SHADER.psh)");
    if (out.empty()) return shadeUsage("say where the image goes (-o OUT.png)");
    if (hardware && precision) return shadeUsage("give --hardware or --precision, not both");
    std::optional<std::string> text = cli::readFile(shaderPath);
    if (!text) return cli::kUserError;
    request.shaderText = *text;
    {
        // Every diagnostic with the file's own places, as `ps11 check` prints them.
        Diagnostics diags;
        std::optional<Program> program = parseAssembly(*text, shaderPath, AssembleOptions{}, diags);
        if (program) validate(*program, diags);
        if (!program || diags.hasErrors()) {
            std::cerr << diags.formatAll();
            return cli::kUserError;
        }
    }
    for (size_t s = 0; s < textures.size(); ++s) {
        if (textures[s].empty()) continue;
        std::string err;
        std::optional<emu::LoadedImage> img = emu::readImage(textures[s], err);
        if (!img) {
            std::cerr << "ps11 shade: " << err << "\n";
            return cli::kUserError;
        }
        request.textures.resize(std::max(request.textures.size(), s + 1));
        request.textures[s] = glare::ShadeTexture{img->hdr ? emu::exposeUnclamped(img->image, exposure) : img->image,
                                                  filters[s]};
    }
    if (glModeGiven && backend != "gl") return shadeUsage("--gl-mode needs --backend gl");
    emu::DeviceOptions options;
    options.hardware = hardware;
    options.precision = precision;
    options.software.skipTiles = !noSkip;
    std::string err;
    if (backend == "gl") {
        options.renderer = ps11test::glRendererFactory(glKind, err, glNative);
        if (!options.renderer) {
            std::cerr << "ps11 shade: the GL renderer is not available: " << err << "\n";
            return cli::kUserError;
        }
    }
    std::optional<emu::FloatImage> result = glare::shade(options, request, err);
    if (!result) {
        std::cerr << "ps11 shade: " << err << "\n";
        return cli::kUserError;
    }
    emu::RgbaImage png = emu::toRgba8(*result);
    for (size_t i = 3; i < png.rgba.size(); i += 4) png.rgba[i] = 255;
    if (!emu::writePng(out, png, err)) {
        std::cerr << "ps11 shade: " << err << "\n";
        return cli::kUserError;
    }
    std::printf("wrote %s (%ux%u)\n", out.c_str(), png.width, png.height);
    return cli::kOk;
}

}  // namespace ps11
