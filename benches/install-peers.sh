# Sourced by the side-by-side benchmark scripts: installs the Debian packages they
# name (plus g++ and pkg-config to build their C++ harnesses) when missing.
# Usage: . "$(dirname "$0")/../install-peers.sh"; install_peers liboctomap-dev ...
install_peers() {
  local need=() pkg
  for pkg in "$@"; do
    dpkg -s "$pkg" >/dev/null 2>&1 || need+=("$pkg")
  done
  command -v g++ >/dev/null 2>&1 || need+=(g++)
  command -v pkg-config >/dev/null 2>&1 || need+=(pkg-config)
  if [ "${#need[@]}" -gt 0 ]; then
    local sudo=""
    [ "$(id -u)" -ne 0 ] && sudo="sudo"
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq "${need[@]}"
  fi
}
