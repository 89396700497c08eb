#!/usr/bin/env bash
# Builds oneTBB with ThreadSanitizer into DIR (default build-tsan/tbb), for make test-tsan.
# Debian's libtbb is not instrumented: TSan cannot see how it hands tasks between threads and
# reports every parallel loop's data as a race. The source is Debian's own (the onetbb source
# package, the same 2021.8.0 as libtbb-dev, fetched with apt through a private deb-src list
# that leaves the system's apt configuration untouched); only libtbb is built (~1 min), and
# dispex loads it with LD_LIBRARY_PATH in place of the system one (same version and ABI).
#   scripts/build-tsan-tbb.sh [DIR]
set -euo pipefail
dir="$(realpath -m "${1:-build-tsan/tbb}")"
[[ -f "$dir/install/lib/libtbb.so.12" ]] && exit 0
mkdir -p "$dir/apt/lists/partial" "$dir/src"
cat > "$dir/apt/deb-src.sources" <<SOURCES
Types: deb-src
URIs: http://deb.debian.org/debian
Suites: bookworm
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
SOURCES
apt=(-o Dir::Etc::SourceList=/dev/null -o "Dir::Etc::SourceParts=$dir/apt"
     -o "Dir::State::Lists=$dir/apt/lists" -o APT::Sandbox::User=root)
echo "build-tsan-tbb: fetching Debian's onetbb source" >&2
apt-get "${apt[@]}" update -qq
version=$(dpkg-query -W -f='${source:Version}' libtbb-dev)
(cd "$dir/src" && { apt-get "${apt[@]}" source --download-only -qq "onetbb=$version" ||
  apt-get "${apt[@]}" source --download-only -qq onetbb; })
tar -xf "$dir"/src/onetbb_*.orig.tar.* -C "$dir/src"
source_dir=$(find "$dir/src" -maxdepth 1 -type d -name 'oneTBB-*' | head -n 1)
log="$dir/build.log"
echo "build-tsan-tbb: building libtbb with -fsanitize=thread (log: $log)" >&2
if ! { cmake -S "$source_dir" -B "$dir/build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
         -DTBB_SANITIZE=thread -DTBB_TEST=OFF -DTBB_EXAMPLES=OFF -DTBB_STRICT=OFF \
         -DTBBMALLOC_BUILD=OFF -DCMAKE_INSTALL_PREFIX="$dir/install" &&
       cmake --build "$dir/build" -j"$(nproc)" --target tbb &&
       cmake --install "$dir/build"; } >"$log" 2>&1; then
  tail -n 20 "$log" >&2
  exit 1
fi
