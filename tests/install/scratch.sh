# Sourced by the install tests, after they set `test` (the ctest name), `build` and `scratch`:
# fail(), a fresh scratch folder with nothing of the user's environment pointing into the build,
# and the build's install_manifest.txt — the list of what the user installed (docs/install.md),
# which cmake --install and cpack rewrite — put back as it was on exit (the tests hold one ctest
# lock). clean_scratch, on success, removes the scratch tree.
fail() {
  echo "$test: $*" >&2
  exit 1
}
unset MFR_PLUGIN_PATH MFR_SHADER_DIR
rm -rf "$scratch" && mkdir -p "$scratch"
manifest=$build/install_manifest.txt
if [ -e "$manifest" ]; then cp -p "$manifest" "$scratch/manifest.saved"; fi
restore() { if [ -e "$scratch/manifest.saved" ]; then cp -p "$scratch/manifest.saved" "$manifest"; else rm -f "$manifest"; fi; }
trap restore EXIT
clean_scratch() { cd / && find "$scratch" -mindepth 1 -maxdepth 1 ! -name manifest.saved -exec rm -rf {} +; }
