#!/usr/bin/env bash
# ctest install.debianPackage: cpack builds the Debian package from the build; its control fields
# name the version and a Depends that dpkg-shlibdeps found (Qt, epoxy, VTK, …) plus the GL
# libraries epoxy opens at run time, every package of which exists here (a Debian 12 machine with
# the build's dependencies); it holds only /usr's programs, plugins and data; and the programs
# unpacked from it render @sample as the build's mfr does.
# Usage: debian_package.sh BUILD_DIR SCRATCH_DIR VERSION
set -euo pipefail
build=$1
scratch=$2
version=$3
test=install.debianPackage
# shellcheck source=scratch.sh
source "$(dirname "${BASH_SOURCE[0]}")/scratch.sh"
cpack --config "$build/CPackConfig.cmake" -B "$scratch" >"$scratch/cpack.log" 2>&1 || fail "cpack failed: $(tail -2 "$scratch/cpack.log")"
deb=$(ls "$scratch"/mfr_*.deb)
[ "$(basename "$deb")" = "mfr_${version}_$(dpkg --print-architecture).deb" ] || fail "unexpected package name $(basename "$deb")"
[ "$(dpkg-deb -f "$deb" Package)" = mfr ] || fail "Package is not mfr"
[ "$(dpkg-deb -f "$deb" Version)" = "$version" ] || fail "Version is not $version"
depends=$(dpkg-deb -f "$deb" Depends)
for need in libqt6widgets6 libepoxy0 libegl1 libgl1 libvtk9.1 libassimp5; do
  grep -qE "(^|, )$need( |,|$)" <<<"$depends" || fail "Depends lacks $need: $depends"
done
# Each dependency (first of its alternatives) is a package installed on this machine.
while read -r dep; do
  pkg=${dep%% *}
  pkg=${pkg%%|*}
  status=$(dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null || true)
  [ "$status" = "install ok installed" ] || fail "Depends names $pkg, which is not an installed package here"
done < <(tr ',' '\n' <<<"$depends" | sed 's/^ *//')
# Only what belongs in a package: programs, plugins, desktop data and docs under /usr.
files=$(dpkg-deb -c "$deb" | awk '$1 !~ /^d/ {print $6}')
bad=$(grep -vE '^\./usr/(bin|lib/mfrview/plugins|share/(applications|icons/hicolor|mime/packages|doc/mfr))/' <<<"$files" || true)
[ -z "$bad" ] || fail "the package holds files outside its folders: $(head -3 <<<"$bad")"
for p in budget csg ghosting hybridvolume; do
  grep -qx "\./usr/lib/mfrview/plugins/mfrview_$p.so" <<<"$files" || fail "the package lacks the $p plugin"
done

dpkg-deb -x "$deb" "$scratch/root"
cd "$scratch"
[ "$(root/usr/bin/mfr --version)" = "mfr $version" ] || fail "the packaged mfr --version says $(root/usr/bin/mfr --version)"
root/usr/bin/mfr render @sample --size 96x72 -o packaged.png >/dev/null || fail "the packaged mfr failed to render @sample"
"$build/app/mfr" render @sample --size 96x72 -o built.png >/dev/null || fail "the build's mfr failed to render @sample"
cmp -s packaged.png built.png || fail "the packaged mfr's @sample differs from the build's"
size=$(stat -c %s "$deb")
clean_scratch  # passed
echo "install.debianPackage: $(basename "$deb"), $size bytes; Depends: $depends"
