#!/usr/bin/env bash
# Prints the directory of Cura's printer definitions, which CuraEngine needs: Debian's `cura`
# package's /usr/share/cura/resources where it is installed, else that package downloaded
# (`apt-get download cura`, without installing Cura and its Qt) and unpacked in DIR.
#
#   resources="$(scripts/cura-resources.sh DIR)"
set -euo pipefail
resources=/usr/share/cura/resources
if [ ! -f "$resources/definitions/fdmprinter.def.json" ]; then
  (cd "$1" && apt-get download cura >/dev/null 2>&1 && dpkg -x cura_*.deb cura)
  resources="$1/cura/usr/share/cura/resources"
fi
echo "$resources"
