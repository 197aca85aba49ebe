#!/usr/bin/env bash
# Installs what manylight needs at run time on Debian/Ubuntu: a Vulkan driver (Mesa's lavapipe
# renders on the CPU when there is no GPU), the Vulkan loader, Xvfb for the window test, and
# for the web demo's tests Chromium, its WebDriver and Python (which serves the page).
# Safe to run again: it installs only what is missing. On other systems install a Vulkan
# driver for your GPU and skip this script.
set -euo pipefail

packages=(mesa-vulkan-drivers libvulkan1 xvfb xauth chromium chromium-driver python3)
missing=()
if command -v dpkg >/dev/null 2>&1; then
    for p in "${packages[@]}"; do
        dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
    done
else
    echo "setup: not a Debian-based system; install a Vulkan driver yourself (e.g. mesa's lavapipe)" >&2
fi

if [ "${#missing[@]}" -gt 0 ]; then
    sudo=""
    if [ "$(id -u)" -ne 0 ]; then
        command -v sudo >/dev/null 2>&1 || { echo "setup: need root or sudo to install ${missing[*]}" >&2; exit 1; }
        sudo="sudo"
    fi
    echo "setup: installing ${missing[*]}" >&2
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# Mesa warns when XDG_RUNTIME_DIR is unset; .cargo/config.toml points it here unless set.
mkdir -p /tmp/manylight-xdg && chmod 700 /tmp/manylight-xdg
