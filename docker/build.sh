#!/usr/bin/env bash
# Builds the housingfe image from docker/Dockerfile, offline-capable, and optionally checks it (`make container`).
#   bash docker/build.sh           build the image ($HOUSINGFE_IMAGE, default housingfe:latest)
#   bash docker/build.sh --check   build, run `housingfe run box-free` in the image without network and compare
#                                  its frequencies with the same run on this machine (relative 1e-9)
#   ... --clean                    remove the image again at the end (CI: an image is 3.3 GB, and images left by
#                                  earlier runs once filled a CI machine's disk mid-build)
# Engine: docker when a Docker daemon answers, else podman (installed with apt when missing) with runc, cgroupfs
# and docker/containers.conf. The base image debian:bookworm-slim is pulled, or made with debootstrap from this
# machine's Debian mirror when no registry is reachable. PyPI packages are downloaded here into ./wheelhouse and
# installed from it inside the image (scripts/bootstrap.sh: --no-index), so the build needs no TLS to PyPI from
# inside the container. See docs/container.md.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$here"
image="${HOUSINGFE_IMAGE:-housingfe:latest}"
base="debian:bookworm-slim"
extras="${HOUSINGFE_EXTRAS:-test}"
venv="${HOUSINGFE_VENV:-$here/.venv}"
wheelhouse="$here/wheelhouse"

check=0
clean=0
for arg in "$@"; do
  case "$arg" in
    --check) check=1 ;;
    --clean) clean=1 ;;
    *) echo "usage: bash docker/build.sh [--check] [--clean]" >&2; exit 2 ;;
  esac
done

log() { echo "container: $*" >&2; }
as_root() { if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi; }

# ---- engine -------------------------------------------------------------------------------------------------
engine="${HOUSINGFE_ENGINE:-}"
if [ -z "$engine" ]; then
  # A docker client without a daemon (as on these CI machines) does not count.
  if command -v docker >/dev/null 2>&1 && docker info >/dev/null 2>&1; then engine=docker; else engine=podman; fi
fi
if [ "$engine" = podman ] && ! command -v podman >/dev/null 2>&1; then
  log "installing podman, runc, debootstrap with apt"
  as_root apt-get update -qq
  as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq \
      podman runc debootstrap uidmap >&2
fi
# Storage driver: overlay (podman's default) works on kernels with native overlayfs; set
# HOUSINGFE_PODMAN_STORAGE=vfs where it does not (slower, more disk).
podman_opts=(--runtime runc --cgroup-manager cgroupfs)
[ -z "${HOUSINGFE_PODMAN_STORAGE:-}" ] || podman_opts+=(--storage-driver "$HOUSINGFE_PODMAN_STORAGE")
ctr() {
  if [ "$engine" = docker ]; then docker "$@"
  else CONTAINERS_CONF="$here/docker/containers.conf" podman "${podman_opts[@]}" "$@"; fi
}

# ---- base image ---------------------------------------------------------------------------------------------
debian_mirror() {
  # The bookworm (not -security) mirror of this machine's apt sources; deb.debian.org when none is found.
  local m=""
  if [ -f /etc/apt/sources.list.d/debian.sources ]; then
    m=$(sed -n 's#^URIs:[[:space:]]*\([^[:space:]]*/debian/\{0,1\}\)\([[:space:]].*\)\{0,1\}$#\1#p' \
        /etc/apt/sources.list.d/debian.sources | head -n1)
  fi
  if [ -z "$m" ] && [ -f /etc/apt/sources.list ]; then
    m=$(sed -n 's#^deb[[:space:]]\{1,\}\(\[[^]]*\][[:space:]]\{1,\}\)\{0,1\}\([^[:space:]]*/debian/\{0,1\}\)[[:space:]]\{1,\}bookworm[[:space:]].*#\2#p' \
        /etc/apt/sources.list | head -n1)
  fi
  echo "${HOUSINGFE_DEBIAN_MIRROR:-${m:-http://deb.debian.org/debian}}"
}

base_image() {
  if [ "$engine" = docker ]; then return; fi   # docker pulls FROM itself
  if ctr image exists "$base"; then log "base image $base present"; return; fi
  if ctr pull -q "docker.io/library/$base" >/dev/null 2>&1; then
    ctr tag "docker.io/library/$base" "$base"; log "pulled $base"; return
  fi
  command -v debootstrap >/dev/null 2>&1 || { log "installing debootstrap"; as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq debootstrap >&2; }
  local mirror tmp t0=$SECONDS
  mirror=$(debian_mirror)
  tmp=$(mktemp -d /tmp/housingfe-rootfs.XXXXXX)
  log "no registry: making $base with debootstrap --variant=minbase bookworm from $mirror"
  as_root debootstrap --variant=minbase bookworm "$tmp/rootfs" "$mirror" >"$tmp/debootstrap.log" 2>&1 \
    || { tail -n 20 "$tmp/debootstrap.log" >&2; exit 1; }
  # Same suites as this machine (bookworm, -updates, -security) so the image gets the same package versions.
  if [ -f /etc/apt/sources.list.d/debian.sources ]; then
    as_root cp /etc/apt/sources.list.d/debian.sources "$tmp/rootfs/etc/apt/sources.list.d/debian.sources"
    as_root rm -f "$tmp/rootfs/etc/apt/sources.list"
  fi
  # What makes the official image "slim": no docs, man pages or locales from later apt installs (~160 MB here).
  printf '%s\n' 'path-exclude /usr/share/doc/*' 'path-include /usr/share/doc/*/copyright' \
      'path-exclude /usr/share/man/*' 'path-exclude /usr/share/groff/*' 'path-exclude /usr/share/info/*' \
      'path-exclude /usr/share/locale/*' 'path-exclude /usr/share/lintian/*' 'path-exclude /usr/share/linda/*' \
    | as_root tee "$tmp/rootfs/etc/dpkg/dpkg.cfg.d/docker" >/dev/null
  # The engine provides hostname and resolv.conf at run time; debootstrap copied this machine's.
  as_root rm -rf "$tmp/rootfs/var/lib/apt/lists/"* "$tmp/rootfs/var/cache/apt/"*.bin \
      "$tmp/rootfs/var/cache/apt/archives/"*.deb "$tmp/rootfs/etc/hostname" "$tmp/rootfs/etc/resolv.conf"
  as_root tar -C "$tmp/rootfs" --numeric-owner -cf - . | ctr import --change 'CMD ["bash"]' - "$base" >/dev/null
  as_root rm -rf "$tmp"
  log "base image $base made in $((SECONDS - t0)) s"
}

# ---- wheelhouse ---------------------------------------------------------------------------------------------
make_wheelhouse() {
  local stamp="$wheelhouse/.complete"
  if [ -f "$stamp" ] && [ ! "$here/pyproject.toml" -nt "$stamp" ] && [ ! "$here/scripts/constraints.txt" -nt "$stamp" ]; then
    log "wheelhouse up to date"; return
  fi
  local py="$venv/bin/python"
  [ -x "$py" ] || py=python3
  # The project's PyPI requirements (+ extras, + build backend for the editable install) from pyproject.toml.
  local reqs
  mapfile -t reqs < <("$py" - "$here/pyproject.toml" "$extras" <<'EOF'
import sys, tomllib
p = tomllib.load(open(sys.argv[1], "rb"))
reqs = list(p["project"]["dependencies"])
for extra in filter(None, sys.argv[2].split(",")):
    reqs += p["project"]["optional-dependencies"][extra]
reqs += p["build-system"]["requires"] + ["wheel"]
print("\n".join(reqs))
EOF
)
  # Wheels for the image's interpreter (CPython 3.11, glibc 2.36, x86_64) whatever this machine is.
  local plat=(--platform manylinux2014_x86_64)
  local v; for v in $(seq 17 36); do plat+=(--platform "manylinux_2_${v}_x86_64"); done
  log "downloading ${#reqs[@]} requirements and their dependencies into wheelhouse/"
  rm -rf "$wheelhouse"
  "$py" -m pip download -q --disable-pip-version-check -d "$wheelhouse" -c "$here/scripts/constraints.txt" \
      --only-binary=:all: --implementation cp --python-version 3.11 --abi cp311 "${plat[@]}" "${reqs[@]}" >&2
  touch "$stamp"
}

# ---- disk ---------------------------------------------------------------------------------------------------
# The image is 3.3 GB and committing its big layer needs about as much again; say so now rather than fail with
# "no space left on device" after a quarter of an hour of building.
need_gb=8
check_disk() {
  local root
  if [ "$engine" = docker ]; then root=$(docker info --format '{{.DockerRootDir}}' 2>/dev/null || echo /var/lib/docker)
  else root=$(ctr info --format '{{.Store.GraphRoot}}' 2>/dev/null || echo /var/lib/containers/storage); fi
  local probe="$root"
  while [ ! -d "$probe" ]; do probe=$(dirname "$probe"); done
  local free_kb
  free_kb=$(df -Pk "$probe" | awk 'NR==2 {print $4}')
  if [ "$free_kb" -lt $((need_gb * 1024 * 1024)) ]; then
    log "FAILED: $((free_kb / 1024)) MB free under $root; building the image needs about $need_gb GB" \
        "(old images: '$engine image prune -a')"
    exit 1
  fi
}

# ---- build --------------------------------------------------------------------------------------------------
t_start=$SECONDS
log "engine: $engine"
check_disk
base_image
make_wheelhouse
t0=$SECONDS
old_id=$(ctr image inspect --format '{{.Id}}' "$image" 2>/dev/null || true)
if [ "$engine" = docker ]; then
  docker build --force-rm -f docker/Dockerfile -t "$image" .
else
  # No layer cache: `COPY .` changes with every commit, so the cached layers were never reused, only left behind
  # (about 3.3 GB per build).
  ctr build --layers=false --force-rm --network host -f docker/Dockerfile -t "$image" .
fi
t_build=$((SECONDS - t0))
log "image $image built in $t_build s ($(ctr image inspect --format '{{.Size}}' "$image" | awk '{printf "%.2f GB", $1/1e9}'))"
# The image this tag named before is now untagged and would stay on disk.
new_id=$(ctr image inspect --format '{{.Id}}' "$image")
if [ -n "$old_id" ] && [ "$old_id" != "$new_id" ]; then
  ctr rmi "$old_id" >/dev/null 2>&1 && log "removed the previous $image (${old_id:0:12})" || true
fi
# --clean: remove the image however the rest ends, a failed check included.
[ "$clean" -eq 0 ] || trap 'ctr rmi "$image" >/dev/null 2>&1 && log "removed $image (--clean)"' EXIT
[ "$check" -eq 1 ] || exit 0

# ---- check: the same scene in the image and on this machine ------------------------------------------------
out="$here/results/container-check"
rm -rf "$out"; mkdir -p "$out"
[ -x "$venv/bin/housingfe" ] || bash "$here/scripts/bootstrap.sh"
opts=(--set output.pictures=false --set output.paraview=false)
user=()
# Rootful docker would leave root-owned files in results/; podman as root or rootless maps to the caller.
[ "$engine" != docker ] || [ "$(id -u)" -eq 0 ] || user=(--user "$(id -u):$(id -g)")
t0=$SECONDS
ctr run --rm --network none "${user[@]}" -v "$out:/work/out:Z" "$image" \
    run box-free --out /work/out/container "${opts[@]}" >"$out/container.log" 2>&1 \
  || { cat "$out/container.log" >&2; log "FAILED: housingfe run box-free in the image"; exit 1; }
t_run=$((SECONDS - t0))
t0=$SECONDS
OPENBLAS_NUM_THREADS=1 "$venv/bin/housingfe" run box-free --out "$out/bare" "${opts[@]}" >"$out/bare.log" 2>&1 \
  || { cat "$out/bare.log" >&2; log "FAILED: housingfe run box-free on this machine"; exit 1; }
t_bare=$((SECONDS - t0))
log "box-free: $t_run s in the container (incl. start), $t_bare s on this machine"
"$venv/bin/python" - "$out/bare/modes.json" "$out/container/modes.json" <<'EOF'
import json, sys
bare, cont = (json.load(open(f)) for f in sys.argv[1:3])
fb, fc = bare["frequencies_hz"], cont["frequencies_hz"]
if len(fb) != len(fc):
    sys.exit(f"container: FAILED: {len(fc)} modes in the container, {len(fb)} on this machine")
rel = max(abs(a - b) / abs(b) for a, b in zip(fc, fb))
print(f"container: {len(fc)} elastic modes, {fc[0]:.6f} .. {fc[-1]:.6f} Hz; DOFs {cont['dofs']} vs {bare['dofs']}; "
      f"max relative difference {rel:.3e}", file=sys.stderr)
if rel > 1e-9 or cont["dofs"] != bare["dofs"]:
    sys.exit("container: FAILED: the image and this machine disagree (tolerance 1e-9 relative)")
print("container: OK: the image reproduces this machine's frequencies", file=sys.stderr)
EOF
log "total $((SECONDS - t_start)) s (build $t_build s)"
