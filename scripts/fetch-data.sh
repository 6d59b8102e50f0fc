#!/usr/bin/env bash
# Fetches the real third-party data of Data/External/ by Debian package name
# (Data/README.md says what each file is, where it comes from and its
# licence). Each package is downloaded with `apt-get download` into
# .deps/data/debs and only the files named below are unpacked from it with
# dpkg-deb; nothing is installed: python3-pcl would pull in Debian's VTK 9.1,
# which conflicts with ParaView's VTK that the project builds against (see
# DESIGN.md). Needs no root unless the apt lists are missing (then it runs
# `apt-get update`, with sudo when not root). Nothing under Data/External/ is
# committed; Data/External/MANIFEST.tsv lists every file with its size,
# SHA-256, package, version and path in the package.
#
#   scripts/fetch-data.sh            fetch what is missing; when the manifest
#                                    matches the files, say so and stop
#   scripts/fetch-data.sh --verify   the same, and check the SHA-256 sums too
#   scripts/fetch-data.sh --force    fetch and convert everything again
set -euo pipefail
cd "$(dirname "$0")/.."

OUT=Data/External
CACHE=.deps/data
PY=/usr/bin/python3

# package | path in the package | copy under $OUT | check (scripts/data/headers.py)
COPIES=(
  "python3-pcl|usr/share/doc/python3-pcl/examples/pcldata/tutorials/table_scene_lms400.pcd|PCL/table_scene_lms400.pcd|pcd 460400 460400 1 binary_compressed x y z intensity distance sid"
  "python3-pcl|usr/share/doc/python3-pcl/examples/pcldata/tutorials/table_scene_mug_stereo_textured.pcd|PCL/table_scene_mug_stereo_textured.pcd|pcd 307200 640 480 binary_compressed x y z rgb"
  "python3-pcl|usr/share/doc/python3-pcl/examples/pcldata/tutorials/correspondence_grouping/milk_cartoon_all_small_clorox.pcd|PCL/milk_cartoon_all_small_clorox.pcd|pcd 307200 640 480 binary_compressed x y z rgba"
  "python3-pcl|usr/share/doc/python3-pcl/examples/pcldata/tutorials/correspondence_grouping/milk.pcd|PCL/milk.pcd|pcd 12575 12575 1 binary_compressed x y z rgba"
  "python3-pcl|usr/share/doc/python3-pcl/examples/official/Surface/bun0.pcd|PCL/bun0.pcd|pcd 112586 112586 1 binary_compressed x y z"
  "python3-pcl|usr/share/doc/python3-pcl/examples/pcldata/tutorials/lamppost.pcd|PCL/lamppost.pcd|pcd 1771 1771 1 ascii x y z"
  "python3-pcl|usr/share/doc/python3-pcl/copyright|PCL/copyright|"
  "opencv-doc|usr/share/doc/opencv-doc/examples/surface_matching/data/rs1_normals.ply|OpenCV/rs1_normals.ply|ply 114373"
  "opencv-doc|usr/share/doc/opencv-doc/copyright|OpenCV/copyright|"
  "invesalius-examples|usr/share/doc/invesalius-examples/copyright|HeadCT/copyright|"
)
# Converted by scripts/data/headct.py into $OUT/HeadCT/{DICOM,PNG,volume.json}.
HEADCT_PKG=invesalius-examples
HEADCT_FILE=usr/share/doc/invesalius-examples/examples/Cranium.inv3

die() { echo "fetch-data: $*" >&2; exit 1; }

force=0 verify=0
for arg in "$@"; do
  case $arg in
    --force) force=1 ;;
    --verify) verify=1 ;;
    *) die "unknown argument '$arg' (--force, --verify)" ;;
  esac
done

# The files' recipe: when these scripts change, everything is made again.
recipe=$(cat scripts/fetch-data.sh scripts/data/{headct,headers,manifest}.py | sha256sum | cut -c1-16)
manifest=$OUT/MANIFEST.tsv

# Done already? The manifest must be of this recipe and name exactly the
# files there, with their sizes.
if [ $force = 0 ] && [ -f $manifest ] && [ "$(head -1 $manifest)" = "# recipe $recipe" ]; then
  if [ "$(awk -F'\t' '!/^#/ {print $1 "\t" $2}' $manifest | sort)" = \
       "$(cd $OUT && find . -type f ! -name MANIFEST.tsv -printf '%P\t%s\n' | sort)" ]; then
    if [ $verify = 1 ]; then
      (cd $OUT && awk -F'\t' '!/^#/ {print $3 "  " $1}' MANIFEST.tsv | sha256sum -c --quiet) ||
        die "$OUT: SHA-256 sums differ from MANIFEST.tsv (scripts/fetch-data.sh --force fetches again)"
    fi
    from=$(awk -F'\t' '!/^#/ {print $4 " " $5}' $manifest | sort -u | paste -sd, - | sed 's/,/, /g')
    checked=$([ $verify = 1 ] && echo ", SHA-256 sums match" || true)
    echo "fetch-data: $OUT is complete ($(grep -vc '^#' $manifest) files, $(du -sh $OUT | cut -f1)," \
      "from $from$checked); nothing to do"
    exit 0
  fi
  echo "fetch-data: the files in $OUT differ from its manifest; fetching again"
fi

[ -x $PY ] && $PY -c 'import numpy, pydicom, vtk' 2>/dev/null ||
  die "$PY cannot import numpy, pydicom and vtk (packages python3-numpy, python3-pydicom," \
    "python3-paraview): run scripts/install-deps.sh (make deps)"

# --- download -----------------------------------------------------------------
SUDO=""
APT_OPTS=()
if [ "$(id -u)" -eq 0 ]; then
  # root downloads as root: no warning that the _apt user cannot write here
  APT_OPTS=(-o APT::Sandbox::User=root)
elif command -v sudo >/dev/null; then
  SUDO="sudo"
fi

packages=($HEADCT_PKG $(printf '%s\n' "${COPIES[@]}" | cut -d'|' -f1 | sort -u))
packages=($(printf '%s\n' "${packages[@]}" | sort -u))
mkdir -p $CACHE/debs
declare -A DEB VERSION
updated=0
for pkg in "${packages[@]}"; do
  deb=$(find $CACHE/debs -maxdepth 1 -name "${pkg}_*.deb" | head -1)
  if [ -z "$deb" ]; then
    if ! apt-cache show --no-all-versions "$pkg" >/dev/null 2>&1 && [ $updated = 0 ]; then
      echo "fetch-data: apt does not know $pkg; running apt-get update"
      if [ "$(id -u)" -ne 0 ] && [ -z "$SUDO" ]; then
        die "package $pkg is not in the apt lists and apt-get update needs root (no sudo here): run 'apt-get update' as root"
      fi
      $SUDO apt-get update -q || die "apt-get update failed"
      updated=1
    fi
    apt-cache show --no-all-versions "$pkg" >/dev/null 2>&1 ||
      die "package $pkg is not known to apt: the Debian 12 (bookworm) main archive must be in the apt sources"
    echo "fetch-data: downloading $pkg"
    rm -rf $CACHE/debs.part && mkdir -p $CACHE/debs.part
    (cd $CACHE/debs.part && apt-get download -q "${APT_OPTS[@]}" "$pkg" >/dev/null) ||
      die "apt-get download $pkg failed"
    mv $CACHE/debs.part/*.deb $CACHE/debs/ && rmdir $CACHE/debs.part
    deb=$(find $CACHE/debs -maxdepth 1 -name "${pkg}_*.deb" | head -1)
  fi
  dpkg-deb -f "$deb" Package 2>/dev/null | grep -qx "$pkg" ||
    die "$deb is not a readable package $pkg (delete it and run again)"
  DEB[$pkg]=$deb
  VERSION[$pkg]=$(dpkg-deb -f "$deb" Version)
done

# --- unpack only the files named above ------------------------------------------
# dpkg-deb --fsys-tarfile is dpkg-deb -x without writing the rest of the
# package (opencv-doc unpacks to 295 MB, of which 10 MB are wanted).
unpack() {  # package, then its files
  local pkg=$1; shift
  local dir=$CACHE/root/$pkg
  rm -rf "$dir" && mkdir -p "$dir"
  dpkg-deb --fsys-tarfile "${DEB[$pkg]}" | tar -x -C "$dir" "${@/#/./}" 2>/dev/null || true
  local f alt
  for f; do
    if [ ! -f "$dir/$f" ]; then
      alt=$(dpkg-deb -c "${DEB[$pkg]}" | awk '{print $NF}' | grep "/$(basename "$f")\$" | sed 's|^\./|/|' | paste -sd' ' - || true)
      die "package $pkg ${VERSION[$pkg]} has no file /$f${alt:+ (a file of that name is at $alt: update scripts/fetch-data.sh)}"
    fi
  done
}
members_of() { printf '%s\n' "${COPIES[@]}" | awk -F'|' -v p="$1" '$1 == p {print $2}'; }

echo "fetch-data: unpacking $(for p in "${packages[@]}"; do printf '%s %s, ' $p ${VERSION[$p]}; done | sed 's/, $//')"
rm -rf $CACHE/root
pids=()
for pkg in "${packages[@]}"; do
  extra=()
  [ "$pkg" = $HEADCT_PKG ] && extra=($HEADCT_FILE)
  # in parallel: opencv-doc's 96 MB of xz take the longest
  unpack "$pkg" $(members_of "$pkg") "${extra[@]}" &
  pids+=($!)
done
for pid in "${pids[@]}"; do wait "$pid" || { kill "${pids[@]}" 2>/dev/null; exit 1; }; done

# --- write the new tree next to the old one, then swap ----------------------------
NEW=$OUT.new
rm -rf $NEW && mkdir -p $NEW
sources=$CACHE/sources.tsv  # path, package, version, path in the package, derivation
rm -f $sources
for entry in "${COPIES[@]}"; do
  IFS='|' read -r pkg member dest check <<<"$entry"
  mkdir -p "$(dirname "$NEW/$dest")"
  cp "$CACHE/root/$pkg/$member" "$NEW/$dest"
  [ -z "$check" ] || $PY scripts/data/headers.py "$NEW/$dest" $check >/dev/null
  printf '%s\t%s\t%s\t/%s\tcopied\n' "$dest" $pkg ${VERSION[$pkg]} "$member" >>$sources
done
$PY scripts/data/headct.py "$CACHE/root/$HEADCT_PKG/$HEADCT_FILE" $NEW/HeadCT \
  $HEADCT_PKG ${VERSION[$HEADCT_PKG]} /$HEADCT_FILE
offset=$($PY -c 'import json, sys; print(json.load(open(sys.argv[1]))["png_offset"])' $NEW/HeadCT/volume.json)
(cd $NEW && find HeadCT/DICOM HeadCT/PNG HeadCT/volume.json -type f | sort) | while read -r f; do
  case $f in
    */DICOM/*) how="one slice of its matrix.dat (HU) as a DICOM CT image, stored = HU + $offset" ;;
    */PNG/*) how="one slice of its matrix.dat as 16-bit grey PNG, value = HU + $offset" ;;
    *) how="shape, spacing, origin, value mapping of the converted volume" ;;
  esac
  printf '%s\t%s\t%s\t/%s\t%s (scripts/data/headct.py)\n' "$f" $HEADCT_PKG \
    ${VERSION[$HEADCT_PKG]} $HEADCT_FILE "$how" >>$sources
done

$PY scripts/data/manifest.py $NEW $sources "$recipe"
rm -rf $OUT && mv $NEW $OUT
rm -rf $CACHE/root
echo "fetch-data: wrote $OUT: $(grep -vc '^#' $manifest) files, $(du -sh $OUT | cut -f1) (list: $manifest)"
