#!/usr/bin/env bash
# Installs what the reliability checks need beyond the build dependencies (Debian 12): clang 14
# with its sanitizer and libFuzzer runtimes (libclang-rt-14-dev) and valgrind. Idempotent. Not
# needed for the README's Quick start or scripts/test.sh.
set -euo pipefail
exec bash "$(dirname "$0")/install-deps.sh" clang libclang-rt-14-dev valgrind
