#!/usr/bin/env bash
# ctest install.installedTreeRuns: `cmake --install` of the build into a scratch prefix, then the
# installed programs run from there, with nothing of the build tree in reach: mfr renders what the
# build's mfr renders, mfrview finds its four plugins beside it (../lib/mfrview/plugins) after the
# whole tree has been moved elsewhere, and finds none once that folder is gone. The desktop entry
# and MIME types are checked by their own tools (desktop-file-validate, update-mime-database).
# Usage: installed_tree.sh BUILD_DIR SCRATCH_DIR
set -euo pipefail
build=$1
scratch=$2
test=install.installedTreeRuns
# shellcheck source=scratch.sh
source "$(dirname "${BASH_SOURCE[0]}")/scratch.sh"
cmake --install "$build" --prefix "$scratch/usr" --strip >"$scratch/install.log" || fail "cmake --install failed"

plugins="mfrview_budget.so mfrview_csg.so mfrview_ghosting.so mfrview_hybridvolume.so"
for f in bin/mfr bin/mfrview share/applications/mfrview.desktop share/icons/hicolor/scalable/apps/mfrview.svg \
  share/mime/packages/mfr.xml share/doc/mfr/README.md share/doc/mfr/LICENSE share/doc/mfr/docs/viewer.md; do
  [ -s "$scratch/usr/$f" ] || fail "the installation lacks $f"
done
for p in $plugins; do [ -s "$scratch/usr/lib/mfrview/plugins/$p" ] || fail "the installation lacks plugin $p"; done

# desktop-file-validate prints errors, warnings and hints; a clean entry prints nothing.
out=$(desktop-file-validate "$scratch/usr/share/applications/mfrview.desktop" 2>&1) || fail "desktop entry: $out"
[ -z "$out" ] || fail "desktop entry: $out"
grep -q '^Exec=mfrview %f$' "$scratch/usr/share/applications/mfrview.desktop" || fail "desktop entry: Exec is not 'mfrview %f'"
# The MIME types, built into a database beside the system's own definitions as a desktop would.
mkdir -p "$scratch/mime/packages"
cp /usr/share/mime/packages/freedesktop.org.xml "$scratch/usr/share/mime/packages/mfr.xml" "$scratch/mime/packages/"
out=$(update-mime-database -V "$scratch/mime" 2>&1) || fail "update-mime-database: $out"
! grep -qi "error\|warning" <<<"$out" || fail "update-mime-database: $(grep -i 'error\|warning' <<<"$out" | head -3)"
for g in 'application/x-mfrscene:\*\.mfrscene' 'application/x-mfrview-session:\*\.mfrsession' 'model/step:\*\.step'; do
  grep -q "$g" "$scratch/mime/globs2" || fail "the MIME database lacks $g"
done
# Files are told by their names and first bytes as a file manager tells them (GIO over this
# database alone): a PDB file that starts with any record, beside Palm's and AportisDoc's *.pdb
# (review 29: MODEL and HETATM files were AportisDoc), a gzipped one, STEP, PLY, legacy VTK, NRRD;
# and a text that merely starts with "ply" is no PLY file.
mkdir -p "$scratch/files" "$scratch/nohome"
cd "$scratch/files"
printf 'MODEL        1\nATOM      1  N   ALA A   1      11.104   6.134  -6.504  1.00  0.00           N\n' >model.pdb
printf 'HETATM    1  C1  LIG A   1       0.000   0.000   0.000  1.00  0.00           C\n' >ligand.pdb
printf 'HEADER    PLANT PROTEIN                           01-JAN-00   1ABC\n' >header.pdb
printf 'x\n' | gzip >packed.pdb.gz
printf 'ISO-10303-21;\nHEADER;\n' >part.stp
printf 'ply\nformat ascii 1.0\n' >mesh.ply
printf '# vtk DataFile Version 3.0\nv\nASCII\n' >volume.vtk
printf 'NRRD0004\n' >volume.nrrd
printf 'ply for the record\n' >note
for pair in model.pdb=chemical/x-pdb ligand.pdb=chemical/x-pdb header.pdb=chemical/x-pdb packed.pdb.gz=chemical/x-pdb \
  part.stp=model/step mesh.ply=model/x-ply volume.vtk=application/x-vtk volume.nrrd=application/x-nrrd note=text/plain; do
  file=${pair%%=*}
  type=$(XDG_DATA_DIRS="$scratch" XDG_DATA_HOME="$scratch/nohome" gio info -a standard::content-type "$file" |
    sed -n 's/^ *standard::content-type: //p')
  [ "$type" = "${pair#*=}" ] || fail "GIO takes $file for '$type', not ${pair#*=}"
done
cd "$scratch"
# Every type the desktop entry opens is one the database knows (the system's or ours).
types=$(sed -n 's/^MimeType=//p' "$scratch/usr/share/applications/mfrview.desktop" | tr ';' ' ')
for t in $types; do
  grep -q "^$t\$" "$scratch/mime/types" || fail "the desktop entry names MIME type $t, which no definition has"
done

# The installed tree works wherever it is moved (the plugins are found relative to the program).
mv "$scratch/usr" "$scratch/moved"
bin=$scratch/moved/bin
cd "$scratch"
"$bin/mfr" render @sample --size 96x72 -o installed.png >/dev/null || fail "the installed mfr failed to render @sample"
"$build/app/mfr" render @sample --size 96x72 -o built.png >/dev/null || fail "the build's mfr failed to render @sample"
cmp -s installed.png built.png || fail "the installed mfr's @sample differs from the build's"
settings=()
for id in budget csg ghosting hybridvolume; do settings+=(--plugin-settings "$id={}"); done
"$bin/mfrview" @sample --window-size 480x360 --screenshot view.png "${settings[@]}" 2>view.err ||
  fail "the installed mfrview did not load its plugins: $(tail -1 view.err)"
[ -s view.png ] || fail "the installed mfrview wrote no screenshot"
# Without the plugin folder nothing else supplies them: the check above can fail.
rm -r "$scratch/moved/lib/mfrview/plugins"
if "$bin/mfrview" @sample --window-size 480x360 --screenshot none.png --plugin-settings 'ghosting={}' 2>none.err; then
  fail "mfrview found a ghosting plugin with its installed plugin folder removed"
fi
grep -q "no plugin of that id is loaded" none.err || fail "mfrview without plugins: $(tail -1 none.err)"
clean_scratch  # passed
echo "install.installedTreeRuns: the installed tree renders @sample as the build does and loads its 4 plugins after a move"
