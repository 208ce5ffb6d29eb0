#!/bin/sh
# Installs what gdr needs to build, test and run, on Debian 12 (bookworm), as root.
# Idempotent: packages already present are left alone; only missing ones are fetched.
# Mesa (lavapipe >= 25, which has VK_EXT_mesh_shader) comes from bookworm-backports. The tests'
# glTF oracle, the Khronos validator, is the npm package gltf-validator (pinned) run by nodejs.
set -eu

GLTF_VALIDATOR="gltf-validator@2.0.0-dev.3.10"

# The validator, into npm's global folder (where tests/io/gltf_validate.mjs looks for it).
install_validator() {
    if ! command -v npm >/dev/null 2>&1; then
        apt-get install -y -q --no-install-recommends npm
    fi
    if [ ! -d "$(npm root -g 2>/dev/null)/gltf-validator" ]; then
        npm install -g --no-fund --no-audit "$GLTF_VALIDATOR"
    fi
}
validator_missing() {
    ! command -v npm >/dev/null 2>&1 || [ ! -d "$(npm root -g 2>/dev/null)/gltf-validator" ]
}

PACKAGES="build-essential cmake pkg-config clang \
libvulkan-dev glslc vulkan-validationlayers \
libmeshoptimizer-dev libmetis-dev libcjson-dev libstb-dev libzstd-dev libpng-dev libjpeg62-turbo-dev \
libxxhash-dev libsquish-dev libclang-rt-14-dev assimp-testmodels valgrind nodejs \
libglfw3-dev libx11-dev xvfb xauth xdotool gnuplot-nox"
BACKPORTS_PACKAGES="mesa-vulkan-drivers"

missing=""
for p in $PACKAGES $BACKPORTS_PACKAGES; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "ok installed"; then
        missing="$missing $p"
    fi
done

# lavapipe must be new enough for mesh shaders, even if an older Mesa is installed.
mesa_version=$(dpkg-query -W -f='${Version}' mesa-vulkan-drivers 2>/dev/null || true)
need_backports_mesa=0
case "$mesa_version" in
    "" ) need_backports_mesa=1 ;;
    * ) if dpkg --compare-versions "$mesa_version" lt 25.0; then need_backports_mesa=1; fi ;;
esac

if [ -z "$missing" ] && [ "$need_backports_mesa" = 0 ] && ! validator_missing; then
    echo "install-deps: everything is installed"
    exit 0
fi

if [ "$(id -u)" != 0 ]; then
    echo "install-deps: missing packages:$missing (or npm's $GLTF_VALIDATOR); run this script as root" >&2
    exit 1
fi

if [ -z "$missing" ] && [ "$need_backports_mesa" = 0 ]; then
    install_validator
    echo "install-deps: done"
    exit 0
fi

. /etc/os-release
if [ "${VERSION_CODENAME:-}" != bookworm ]; then
    echo "install-deps: warning: written for Debian 12 (bookworm), this is ${PRETTY_NAME:-unknown}" >&2
fi

if ! grep -rqs "bookworm-backports" /etc/apt/sources.list /etc/apt/sources.list.d/; then
    echo "deb http://deb.debian.org/debian bookworm-backports main" \
        > /etc/apt/sources.list.d/bookworm-backports.list
fi

export DEBIAN_FRONTEND=noninteractive
apt-get update -q
regular=""
for p in $missing; do
    case " $BACKPORTS_PACKAGES " in *" $p "*) ;; *) regular="$regular $p" ;; esac
done
if [ -n "$regular" ]; then
    # shellcheck disable=SC2086
    apt-get install -y -q --no-install-recommends $regular
fi
# shellcheck disable=SC2086
apt-get install -y -q --no-install-recommends -t bookworm-backports $BACKPORTS_PACKAGES
install_validator
echo "install-deps: done"
