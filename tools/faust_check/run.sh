#!/usr/bin/env bash
# Hand check of `modal export --faust` with the real Faust compiler (docs/faust.md):
# compiles the exported model to C++, renders its impulse response at every
# excitation position, and fits damped sinusoids at the model's own frequencies
# and decay rates. Needs faust (apt-get install faust), g++ and numpy.
# Usage: tools/faust_check/run.sh MODEL.lib N_EXPOS [PYTHON]
set -euo pipefail
lib=$(realpath "$1"); n=$2; py=${3:-python3}
here=$(cd "$(dirname "$0")" && pwd); work=$(mktemp -d); cd "$work"
cp "$lib" model.lib
for ((p = 0; p < n; p++)); do
  printf 'import("stdfaust.lib");\nimport("model.lib");\nprocess = (1-1'"'"') : modalModel(%d,1);\n' "$p" > s.dsp
  faust -lang cpp -i -cn mydsp s.dsp -o s.h
  g++ -O1 -I. -o render "$here/render.cpp"
  ./render "s$p.raw"
done
"$py" "$here/fit.py" model.lib "$n"
rm -rf "$work"
