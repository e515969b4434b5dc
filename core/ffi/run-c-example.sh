#!/usr/bin/env bash
# Builds lucent-ffi's static library, compiles examples/embed.c against include/lucent.h with
# the system C compiler (`cc`, strict C99, warnings as errors) and runs it; a non-zero exit
# means the build or one of the example's checks failed. `--release` links the optimised
# library instead of the debug one.
set -euo pipefail
cd "$(dirname "$0")/../.."

profile=debug
cargo_flags=()
if [ "${1:-}" = "--release" ]; then
    profile=release
    cargo_flags=(--release)
fi
cargo build -p lucent-ffi --lib "${cargo_flags[@]}"
library="${CARGO_TARGET_DIR:-target}/$profile/liblucent_ffi.a"

scratch="$(mktemp -d)"
trap 'rm -rf "$scratch"' EXIT
# The libraries Rust's standard library needs on Linux (`--print native-static-libs`).
cc -std=c99 -pedantic -Wall -Wextra -Werror -I core/ffi/include core/ffi/examples/embed.c \
    "$library" -lm -lpthread -ldl -o "$scratch/embed"
# The header is C++-compatible too (extern "C"): check it where a C++ compiler exists.
if command -v c++ > /dev/null 2>&1; then
    echo '#include "lucent.h"' | c++ -std=c++11 -Wall -Wextra -Werror -I core/ffi/include \
        -x c++ -fsyntax-only -
fi
"$scratch/embed"
