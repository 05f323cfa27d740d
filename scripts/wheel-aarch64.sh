#!/usr/bin/env bash
# The arbor-rays wheel for Linux aarch64 (Docker on Apple silicon, Graviton, Raspberry Pi 4/5), cross-built
# on an x86_64 Debian machine and tested there: maturin builds the abi3 wheel with Rust's aarch64 target and
# Debian's cross linker, then the Python suite runs against it inside an aarch64 CPython under qemu-user
# (Debian's own python3.11 for arm64, unpacked into a folder, with the aarch64 wheels of numpy, pytest,
# trimesh and rtree from PyPI). Nothing is installed into the system's Python.
#
# Usage: scripts/wheel-aarch64.sh [OUT]   (OUT: where the wheel goes, default target/wheels-aarch64)
# Needs root for apt-get (gcc-aarch64-linux-gnu, qemu-user-static, the arm64 packages); about 4 minutes of
# compiling on 2 idle cores, then 3 minutes of tests under emulation.
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-target/wheels-aarch64}"
work="target/aarch64-python"
venv=".ci/py-venv"

rustup target list --installed | grep -qx aarch64-unknown-linux-gnu || rustup target add aarch64-unknown-linux-gnu
if ! command -v aarch64-linux-gnu-gcc >/dev/null || ! command -v qemu-aarch64-static >/dev/null; then
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends gcc-aarch64-linux-gnu libc6-dev-arm64-cross qemu-user-static
fi
[ -x "$venv/bin/maturin" ] || { python3 -m venv "$venv"; "$venv/bin/pip" install -q --disable-pip-version-check maturin; }

# The wheel. Debug info off: it is for users, and it halves the link.
rm -rf "$out"
CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_LINKER=aarch64-linux-gnu-gcc CARGO_PROFILE_RELEASE_DEBUG=0 \
  "$venv/bin/maturin" build --release --quiet -m crates/arbor-py/Cargo.toml --target aarch64-unknown-linux-gnu -o "$out"
wheel=$(ls "$out"/arbor_rays-*-manylinux_*_aarch64.whl)
echo "built $wheel"

# An aarch64 CPython: Debian's arm64 packages unpacked into a root (no dpkg database touched).
root="$work/root"
if [ ! -x "$root/usr/bin/python3.11" ]; then
  dpkg --print-foreign-architectures | grep -qx arm64 || { dpkg --add-architecture arm64; apt-get update -qq; }
  mkdir -p "$work/debs" "$root"
  (cd "$work/debs" && apt-get download -qq libc6:arm64 libgcc-s1:arm64 libstdc++6:arm64 zlib1g:arm64 \
    libexpat1:arm64 libffi8:arm64 libbz2-1.0:arm64 liblzma5:arm64 libssl3:arm64 libcrypt1:arm64 \
    libuuid1:arm64 libsqlite3-0:arm64 libtinfo6:arm64 libncursesw6:arm64 libreadline8:arm64 \
    libnsl2:arm64 libtirpc3:arm64 libgssapi-krb5-2:arm64 libkrb5-3:arm64 libk5crypto3:arm64 \
    libkrb5support0:arm64 libcom-err2:arm64 libkeyutils1:arm64 libgomp1:arm64 \
    python3.11-minimal:arm64 libpython3.11-minimal:arm64 libpython3.11-stdlib:arm64)
  for deb in "$work"/debs/*.deb; do dpkg-deb -x "$deb" "$root"; done
fi

# Its packages: aarch64 wheels from PyPI, unzipped beside the one under test.
site="$work/site"
rm -rf "$site" && mkdir -p "$site" "$work/wheels"
"$venv/bin/pip" download -q --disable-pip-version-check --only-binary=:all: -d "$work/wheels" \
  --platform manylinux2014_aarch64 --platform manylinux_2_28_aarch64 --python-version 3.11 \
  --implementation cp --abi cp311 numpy pytest trimesh rtree
for w in "$work"/wheels/*.whl "$wheel"; do python3 -m zipfile -e "$w" "$site"; done

py() { PYTHONPATH="$(pwd)/$site" qemu-aarch64-static -L "$(pwd)/$root" "$(pwd)/$root/usr/bin/python3.11" "$@"; }
py -c 'import platform, arbor_rays; print("arbor_rays", arbor_rays.__version__, "on", platform.machine())'
# The suite as .ci/run runs it against the x86_64 wheel (the render test compares with the CLI binary,
# which runs natively), but for the comparison with trimesh's pure-Python intersector on the shared
# meshes (about 30 times slower under emulation, and it checks the adapter, not the platform) and the
# import under a bad ARBOR_MAX_ISA, which starts a new interpreter that runs here only through qemu.
bin="$(pwd)/target/release/arbor"
[ -x "$bin" ] || cargo build --release -p arbor-cli
(cd target && ARBOR_BIN="$bin" PYTHONPATH="$(pwd)/../$site" qemu-aarch64-static -L "$(pwd)/../$root" \
  "$(pwd)/../$root/usr/bin/python3.11" -m pytest -q -p no:cacheprovider ../crates/arbor-py/tests/python \
  -k "not agrees_with_trimesh_ray_triangle and not unknown_kernel_cap")
