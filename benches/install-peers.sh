# Sourced by the side-by-side benchmark scripts: installs the Debian packages they
# name (plus g++ and pkg-config to build their C++ harnesses) when missing, with
# scripts/debian-install.
# Usage: . "$(dirname "$0")/../install-peers.sh"; install_peers liboctomap-dev ...
install_peers() {
  "$(dirname "${BASH_SOURCE[0]}")/../scripts/debian-install" "$@" g++ pkg-config
}
