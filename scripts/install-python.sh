#!/usr/bin/env bash
# Makes `import vkpose` work in this machine's python3 without copying anything or using the
# network: writes a vkpose.pth file (one line: build/release/python) into the user's
# site-packages of `python3` (and of /usr/bin/python3 if that is another interpreter), or into
# the active virtual environment. An interpreter of the same version that lacks Debian's numpy
# (a pyenv or a self-built Python) also gets Debian's dist-packages on its path, where
# install-deps.sh put numpy and OpenCV. Run after building; scripts/demo.sh runs it.
# Undo: python3 -c 'import site; print(site.getusersitepackages())', delete vkpose.pth there.
set -euo pipefail
cd "$(dirname "$0")/.."
package="$(pwd)/build/release/python"
extension=$(ls "$package"/vkpose/_vkpose.*.so 2>/dev/null | head -1 || true)
if [ -z "$extension" ]; then
  echo "install-python: $package/vkpose is not built yet: cmake --preset release && cmake --build --preset release" >&2
  exit 1
fi
# The Python version the extension was built for, from its name (_vkpose.cpython-311-...so).
built=$(basename "$extension" | sed -n 's/.*cpython-\([0-9]\)\([0-9]*\)-.*/\1.\2/p')
debian_packages=/usr/lib/python3/dist-packages

declare -A lines   # site folder -> lines of its vkpose.pth
declare -a pythons=()
for py in "$(command -v python3 || true)" /usr/bin/python3; do
  [ -n "$py" ] && [ -x "$py" ] || continue
  real=$(readlink -f "$(command -v "$py")")
  version=$("$py" -c 'import sys; print("%d.%d" % sys.version_info[:2])')
  if [ "$version" != "$built" ]; then
    echo "install-python: $py is Python $version; vkpose is built for $built (rebuild with -DPython3_EXECUTABLE=$py)"
    continue
  fi
  site=$("$py" -c 'import site, sys, sysconfig
in_venv = sys.prefix != sys.base_prefix
print(sysconfig.get_paths()["purelib"] if in_venv or not site.ENABLE_USER_SITE else site.getusersitepackages())')
  entry="${lines[$site]:-}"
  [[ "$entry" == *"$package"* ]] || entry+="$package"$'\n'
  if ! "$py" -c 'import numpy' 2>/dev/null && [ -d "$debian_packages" ] && [[ "$entry" != *"$debian_packages"* ]]; then
    entry+="$debian_packages"$'\n'
  fi
  lines[$site]="$entry"
  pythons+=("$py")
done
if [ ${#pythons[@]} -eq 0 ]; then
  echo "install-python: no python3 of version $built found" >&2
  exit 1
fi
for site in "${!lines[@]}"; do
  mkdir -p "$site"
  printf '%s' "${lines[$site]}" > "$site/vkpose.pth"
  echo "install-python: wrote $site/vkpose.pth"
done
for py in "${pythons[@]}"; do
  "$py" -c 'import vkpose; print("install-python: %s imports vkpose %s" % (__import__("sys").executable, vkpose.__version__))'
done
