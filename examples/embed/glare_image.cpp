// Runs one glare technique (Sousa's adaptive glare, its published settings) over an image file,
// or over a generated image when none is given, and writes the output PNG.
//   glare_image [IN.png|.hdr|.exr] OUT.png
#include <cstdio>
#include <optional>
#include <string>

#include "emu/image_file.h"
#include "glare/runner.h"
#include "glare/technique.h"

int main(int argc, char** argv) {
    if (argc != 2 && argc != 3) {
        std::fprintf(stderr, "usage: glare_image [IN] OUT.png\n");
        return 2;
    }
    std::string error;
    emu::FloatImage input;
    if (argc == 3) {
        std::optional<emu::LoadedImage> loaded = emu::readImage(argv[1], error);
        if (!loaded) {
            std::fprintf(stderr, "%s\n", error.c_str());
            return 1;
        }
        input = loaded->image;
    } else {
        // 64x64, dark, with one bright square in the middle: something to glare.
        input.width = input.height = 64;
        input.rgba.assign(64 * 64 * 4, 0.1f);
        for (uint32_t y = 28; y < 36; ++y)
            for (uint32_t x = 28; x < 36; ++x)
                for (int c = 0; c < 3; ++c) input.rgba[(y * 64 + x) * 4 + c] = 1.0f;
        for (size_t i = 3; i < input.rgba.size(); i += 4) input.rgba[i] = 1.0f;
    }

    // The technique and its settings (glare/technique.h).
    const glare::Technique* technique = glare::findTechnique("adaptive");
    std::optional<glare::Settings> settings = technique ? glare::presetSettings(*technique, "published") : std::nullopt;
    if (!settings) return 1;

    // A runner owns the device (software renderer, the default 1.1-class card) and the frame.
    glare::RunnerOptions options;
    options.width = input.width;
    options.height = input.height;
    glare::Runner runner(options);
    glare::FrameResult frame;
    if (!runner.setImage(input, error) || !runner.runFrame(*technique, *settings, 0, 1, frame, error)) {
        std::fprintf(stderr, "%s\n", error.c_str());
        return 1;
    }
    std::optional<emu::RgbaImage> output = runner.readOutput(error);
    if (!output || !emu::writePng(argv[argc - 1], *output, error)) {
        std::fprintf(stderr, "%s\n", error.c_str());
        return 1;
    }
    const std::string name(technique->name());
    std::printf("%s: %zu passes, %ux%u -> %s\n", name.c_str(), frame.passes.size(), output->width, output->height,
                argv[argc - 1]);
    return 0;
}
