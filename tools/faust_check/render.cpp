// One second of the compiled model's response to the impulse in its process, at 48 kHz, as raw f32.
#include <cstdio>
#include "faust/gui/meta.h"
#include "faust/gui/UI.h"
#include "faust/dsp/dsp.h"
#include "s.h"
int main(int argc, char** argv) {
    if (argc < 2) return 2;
    mydsp d;
    d.init(48000);
    const int n = 48000;
    static float out[n];
    float* outs[1] = {out};
    float* ins[1] = {nullptr};
    d.compute(n, ins, outs);
    FILE* f = std::fopen(argv[1], "wb");
    if (!f) return 1;
    std::fwrite(out, sizeof(float), n, f);
    return std::fclose(f);
}
