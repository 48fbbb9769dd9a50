#!/usr/bin/env bash
# Builds the Debian package from a build folder (cpack -G DEB) and checks it as far as an
# offline machine allows (doc/install.md): control fields and Depends, contents, no file that
# an installed package (Debian's colmap above all) owns, dpkg --dry-run, an apt simulation
# from an empty dpkg status against Debian's package lists, and the unpacked binaries run
# from a temporary root away from the source tree. Exits non-zero on the first failure.
#   scripts/check_deb.sh [BUILD_DIR]      (default: $FVS_BUILD_DIR or build)
set -euo pipefail
cd "$(dirname "$0")/.."
SRC="$PWD"
BUILD="$(cd "${1:-${FVS_BUILD_DIR:-build}}" && pwd)"
TMP="$(mktemp -d)"
trap 'rm -rf "$TMP"' EXIT

fail() { echo "check_deb: FAIL: $*" >&2; exit 1; }
ok() { echo "check_deb: ok: $*"; }
note() { echo "check_deb: not checked: $*"; }

# 1. The package.
rm -f "$BUILD"/colmap-fvs_*.deb
if ! (cd "$BUILD" && cpack -G DEB >"$TMP/cpack.log" 2>&1); then
  tail -n 30 "$TMP/cpack.log" >&2
  fail "cpack -G DEB in $BUILD"
fi
debs=("$BUILD"/colmap-fvs_*.deb)
[[ ${#debs[@]} -eq 1 && -f "${debs[0]}" ]] || fail "expected one colmap-fvs_*.deb in $BUILD"
DEB="${debs[0]}"
ok "built $(basename "$DEB") ($(du -h "$DEB" | cut -f1))"

# 2. Control fields: the name, and Depends on what the binaries need at run time.
[[ "$(dpkg-deb -f "$DEB" Package)" == colmap-fvs ]] || fail "Package is not colmap-fvs"
depends="$(dpkg-deb -f "$DEB" Depends)"
for want in colmap libtorch libopenimageio libqt5widgets5 libqt5gui5 libgoogle-glog libc6 \
  libstdc++6; do
  [[ ", $depends" == *", $want"* ]] || fail "Depends lacks $want: $depends"
done
ok "Depends: $depends"
ok "Recommends: $(dpkg-deb -f "$DEB" Recommends)"

# 3. Contents: what a user runs, the models folder, docs, man page; never /usr/bin/colmap,
# nothing outside /usr.
dpkg-deb -c "$DEB" | awk '{print $6}' | sed 's|^\./|/|; s|/$||' | grep -v '^$' | grep -v '^/$' \
  >"$TMP/files"
for want in /usr/bin/colmap-fvs /usr/bin/fvs_train_main /usr/lib/colmap-fvs/bin/colmap \
  /usr/lib/colmap-fvs/bin/.fvs_front_door /usr/share/colmap-fvs/models/README.md \
  /usr/share/doc/colmap-fvs/README.md /usr/share/doc/colmap-fvs/doc/install.md \
  /usr/share/man/man1/colmap-fvs.1; do
  grep -qx -- "$want" "$TMP/files" || fail "the package lacks $want"
done
for model in "$SRC"/models/*; do
  grep -qx -- "/usr/share/colmap-fvs/models/$(basename "$model")" "$TMP/files" ||
    fail "the package lacks models/$(basename "$model")"
done
! grep -qx /usr/bin/colmap "$TMP/files" || fail "the package installs /usr/bin/colmap"
! grep -qx /usr/bin/.fvs_front_door "$TMP/files" ||
  fail "the package puts a front-door marker in /usr/bin (it would hide Debian's colmap)"
! grep -v '^/usr' "$TMP/files" | grep -q . || fail "files outside /usr: $(grep -v '^/usr' "$TMP/files")"
ok "$(wc -l <"$TMP/files") paths, all under /usr; /usr/bin/colmap left to Debian's colmap"

# 4. No collision: no file of the package belongs to an installed package, nor to Debian's
# colmap package (installed, or its .deb in the apt cache).
dpkg-deb -c "$DEB" | grep -v '^d' | awk '{print $6}' | sed 's|^\./|/|' >"$TMP/plain_files"
while read -r f; do
  if owner="$(dpkg-query -S "$f" 2>/dev/null)"; then fail "$f already belongs to: $owner"; fi
done <"$TMP/plain_files"
{
  dpkg -L colmap 2>/dev/null || true
  for cached in /var/cache/apt/archives/colmap_*.deb; do
    [[ -f "$cached" ]] && dpkg-deb -c "$cached" | awk '{print $6}' | sed 's|^\./|/|'
  done
} | sort -u >"$TMP/colmap_files"
if [[ -s "$TMP/colmap_files" ]]; then
  clash="$(sort -u "$TMP/plain_files" | comm -12 - "$TMP/colmap_files")"
  [[ -z "$clash" ]] || fail "shares files with Debian's colmap: $clash"
  ok "no file owned by an installed package; none shared with Debian's colmap ($(wc -l <"$TMP/colmap_files") paths)"
else
  ok "no file owned by an installed package"
  note "Debian's colmap file list (neither installed nor in the apt cache)"
fi

# 5. dpkg on this machine: would it install, dependencies satisfied?
if [[ $EUID -eq 0 ]]; then
  dpkg --dry-run -i "$DEB" >"$TMP/dpkg.log" 2>&1 || { cat "$TMP/dpkg.log" >&2; fail "dpkg --dry-run -i"; }
  ok "dpkg --dry-run -i (this machine's installed packages satisfy Depends)"
else
  note "dpkg --dry-run -i (needs root)"
fi

# 6. apt from an empty dpkg status (a machine with nothing installed): does Debian's archive,
# as this machine's package lists know it, resolve every dependency?
if compgen -G "/var/lib/apt/lists/*_Packages*" >/dev/null; then
  : >"$TMP/status"
  if apt-get -o Dir::State::status="$TMP/status" -o Debug::NoLocking=1 --simulate \
    install "$DEB" >"$TMP/apt.log" 2>&1 && grep -q '^Inst colmap-fvs ' "$TMP/apt.log"; then
    ok "apt-get install --simulate from an empty dpkg status: $(grep -c '^Inst ' "$TMP/apt.log") packages, colmap-fvs and its dependencies, all resolved"
  else
    tail -n 20 "$TMP/apt.log" >&2
    fail "apt-get install --simulate from an empty dpkg status"
  fi
else
  note "apt simulation (no package lists under /var/lib/apt/lists)"
fi

# 7. The unpacked package runs on its own: from a temporary root, another working folder, no
# path of the checkout in the environment, the source tree hidden under an empty tmpfs when a
# private mount namespace can be made.
ROOT="$TMP/root"
dpkg -x "$DEB" "$ROOT"
for bin in "$ROOT/usr/bin/colmap-fvs" "$ROOT/usr/bin/fvs_train_main"; do
  ! readelf -d "$bin" | grep -Eq 'RPATH|RUNPATH' || fail "$(basename "$bin") has an RPATH"
  ! grep -a -q -F "$SRC" "$bin" || fail "$(basename "$bin") names the source tree $SRC"
  ! grep -a -q -F "$BUILD" "$bin" || fail "$(basename "$bin") names the build tree $BUILD"
  missing="$(ldd "$bin" | grep 'not found' || true)"
  [[ -z "$missing" ]] || fail "$(basename "$bin"): $missing"
done
ok "binaries: no RPATH, no source or build path, every library found by ldd"
hide=()
if unshare -m sh -c "mount -t tmpfs none '$SRC' && test ! -e '$SRC/CMakeLists.txt'" 2>/dev/null; then
  hide=(unshare -m sh -c "mount -t tmpfs none '$SRC'; mount -t tmpfs none '$BUILD' 2>/dev/null; exec \"\$@\"" sh)
  hidden="source tree hidden"
else
  hidden="source tree not hidden (no mount namespace)"
fi
try_run() {
  (cd "$TMP" && env -i HOME="$TMP" PATH="$1" FVS_QUIET=1 QT_QPA_PLATFORM=offscreen \
    OMP_WAIT_POLICY=PASSIVE "${hide[@]}" timeout 300 "${@:2}") >"$TMP/run.log" 2>&1
}
run() { try_run "$@" || { cat "$TMP/run.log" >&2; fail "${*:2}"; }; }
run /usr/bin:/bin "$ROOT/usr/bin/colmap-fvs" help
grep -q feature_extractor "$TMP/run.log" || fail "colmap-fvs help does not list COLMAP's commands"
grep -q view_synthesis_prepare "$TMP/run.log" || fail "colmap-fvs help does not list ours"
run "$ROOT/usr/lib/colmap-fvs/bin:/usr/bin:/bin" colmap help
grep -q feature_extractor "$TMP/run.log" || fail "lib/colmap-fvs/bin/colmap does not reach the real COLMAP"
run /usr/bin:/bin "$ROOT/usr/bin/colmap-fvs" view_synthesis_synthetic --output_path "$TMP/ws" \
  --SyntheticScene.num_views 6 --SyntheticScene.width 96 --SyntheticScene.height 72 \
  --SyntheticScene.write_proxy_mesh 1
run /usr/bin:/bin "$ROOT/usr/bin/colmap-fvs" view_synthesis --workspace_path "$TMP/ws" \
  --output_path "$TMP/ulr" --method ulr --orbit 2
[[ "$(ls "$TMP/ulr"/*.png | wc -l)" -eq 2 ]] || fail "view_synthesis --method ulr wrote no images"
if [[ ! -f "$SRC/models/fvs_agg.safetensors" ]]; then
  ! try_run /usr/bin:/bin "$ROOT/usr/bin/colmap-fvs" view_synthesis --workspace_path "$TMP/ws" \
    --output_path "$TMP/none" --method fvs_agg --orbit 1 || fail "fvs_agg rendered without weights"
  grep -q "needs model weights" "$TMP/run.log" || fail "no weights: $(cat "$TMP/run.log")"
fi
if ls "$SRC"/models/*.safetensors >/dev/null 2>&1; then
  variant="$(basename "$(ls "$SRC"/models/*.safetensors | head -n 1)" .safetensors)"
  run /usr/bin:/bin "$ROOT/usr/bin/colmap-fvs" view_synthesis --workspace_path "$TMP/ws" \
    --output_path "$TMP/shipped" --method "$variant" --orbit 1
  grep -q "using the shipped model $ROOT/usr/share/colmap-fvs/models/$variant.safetensors" \
    "$TMP/run.log" || fail "the unpacked $variant model was not used"
  ok "--method $variant found the unpacked shipped model"
else
  note "a shipped model (models/ holds none; tests/exe/install_test.cc checks the lookup)"
fi
ok "unpacked binaries ran from $ROOT ($hidden): help, COLMAP found, view_synthesis_synthetic, view_synthesis --method ulr"
# 8. A real `apt install ./colmap-fvs_*.deb` (and `apt remove`), inside a throwaway copy of
# this system: an overlay of / whose changes go to a tmpfs, in a private mount namespace, with
# /work (the checkouts) covered. Offline, so it shows the install on a machine that already
# has every dependency, not the download. Needs root and overlayfs; skipped otherwise.
OV="$TMP/overlay"
mkdir -p "$OV/changes" "$OV/root"
cat >"$TMP/in_chroot.sh" <<'IN'
set -eu
export PATH=/usr/sbin:/usr/bin:/sbin:/bin DEBIAN_FRONTEND=noninteractive
before="$(md5sum /usr/bin/colmap)"
apt-get install -y --no-install-recommends /var/tmp/check_deb/*.deb >/apt_install.log 2>&1 || { cat /apt_install.log; exit 11; }
dpkg -s colmap-fvs | grep -q '^Status: install ok installed' || exit 12
[ "$(md5sum /usr/bin/colmap)" = "$before" ] || { echo "/usr/bin/colmap changed"; exit 13; }
cd /tmp
FVS_QUIET=1 QT_QPA_PLATFORM=offscreen colmap-fvs help >/help.log 2>&1 || { cat /help.log; exit 14; }
grep -q feature_extractor /help.log && grep -q view_synthesis_prepare /help.log || exit 15
FVS_QUIET=1 colmap-fvs view_synthesis_synthetic --output_path /tmp/ws --SyntheticScene.num_views 6 \
  --SyntheticScene.width 96 --SyntheticScene.height 72 --SyntheticScene.write_proxy_mesh 1 || exit 16
FVS_QUIET=1 OMP_WAIT_POLICY=PASSIVE colmap-fvs view_synthesis --workspace_path /tmp/ws \
  --output_path /tmp/ulr --method ulr --orbit 1 || exit 17
man -w colmap-fvs >/dev/null 2>&1 || [ -f /usr/share/man/man1/colmap-fvs.1 ] || exit 18
apt-get remove -y colmap-fvs >/apt_remove.log 2>&1 || { cat /apt_remove.log; exit 19; }
[ ! -e /usr/bin/colmap-fvs ] && [ ! -e /usr/lib/colmap-fvs ] && [ -x /usr/bin/colmap ] || exit 20
IN
if [[ $EUID -eq 0 ]] && unshare -m sh -c "mount -t tmpfs none '$OV/changes' && mkdir '$OV/changes/u' '$OV/changes/w' && mount -t overlay overlay -o 'lowerdir=/,upperdir=$OV/changes/u,workdir=$OV/changes/w' '$OV/root'" 2>/dev/null; then
  unshare -m sh -c "
    set -e
    mount -t tmpfs none '$OV/changes'; mkdir '$OV/changes/u' '$OV/changes/w'
    mount -t overlay overlay -o 'lowerdir=/,upperdir=$OV/changes/u,workdir=$OV/changes/w' '$OV/root'
    mount -t proc proc '$OV/root/proc'; mount --rbind /dev '$OV/root/dev'; mount --rbind /sys '$OV/root/sys'
    mount -t tmpfs none '$OV/root/tmp'
    [ -d '$OV/root/work' ] && mount -t tmpfs none '$OV/root/work'
    mkdir -p '$OV/root/var/tmp/check_deb'; cp '$DEB' '$OV/root/var/tmp/check_deb/'
    cp '$TMP/in_chroot.sh' '$OV/root/in_chroot.sh'
    exec chroot '$OV/root' sh /in_chroot.sh" >"$TMP/overlay.log" 2>&1 ||
    { cat "$TMP/overlay.log" >&2; fail "apt install / run / apt remove in an overlay of this system"; }
  ok "apt install ./$(basename "$DEB") in a throwaway overlay of this system (/work hidden): installed, /usr/bin/colmap untouched, colmap-fvs help/view_synthesis_synthetic/view_synthesis ran, apt remove left nothing"
else
  note "a real apt install (needs root and overlayfs in a private mount namespace)"
fi

echo "check_deb: all checks passed: $DEB"
