#!/usr/bin/env bash
# usage: [ST_DIR=DIR] [ST_MIRROR=DIR | ST_GIT_URL=TEMPLATE] scripts/fetch-st.sh [f4|g4|h7...]
# Fetch ST's public STM32Cube sources that `make firmware` builds against, at pinned tags,
# into ST_DIR (default build/st; never committed): the HAL driver and CMSIS device package of
# each FAMILY (f4, g4, h7; default: all three) and the CMSIS core headers. Each lands in
# ST_DIR/<repository> (only the folders a build uses) with a .tag file naming what was
# fetched; a repository already there at its pinned tag is left alone. f4 and g4 are the
# firmware's boards; h7 serves a compile check of the port on a Cortex-M7 with its D-cache.
# Where from: by default https://github.com/STMicroelectronics/<repository>.git (a shallow
# clone of the tag). ST_MIRROR=DIR takes each repository from DIR/<repository> or
# DIR/<repository>.git instead (any git repository holding the tag, bare or not: exported with
# git archive). ST_GIT_URL is the general form, a template where %s stands for the repository
# name (a URL or a local path), e.g. ST_GIT_URL=/srv/git/STMicroelectronics/%s.git.
set -euo pipefail

dest=${ST_DIR:-build/st}
families=("$@")
[ ${#families[@]} -eq 0 ] && families=(f4 g4 h7)

# The pinned versions (components of STM32CubeF4 1.28, STM32CubeG4 1.6, STM32CubeH7 1.11).
# "name tag commit folders...": the tag must name that commit (a moved tag or a mirror holding
# something else stops the fetch); only these folders are kept.
repos=("cmsis_core v5.9.0 1a2f783395dd72778a98ebe7771f36ca1c30a35e Include")
for f in "${families[@]}"; do
    case $f in
    f4) repos+=("stm32f4xx_hal_driver v1.8.3 c2e1406d7ea4b73aa42b98ddeb75a8670b1a5a16 Inc Src"
                "cmsis_device_f4 v2.6.9 3b64b7b0b546cefe84f13c65508126eea58b97d8 Include Source/Templates") ;;
    g4) repos+=("stm32g4xx_hal_driver v1.2.4 63c724f62a299f976ab8e413865f439cf0402168 Inc Src"
                "cmsis_device_g4 v1.2.4 f4ee399953e3b5c437788526e93b10efa5fad4fa Include Source/Templates") ;;
    h7) repos+=("stm32h7xx_hal_driver v1.11.3 fec141ce999da655a48e1a15db83a72d564a1312 Inc Src"
                "cmsis_device_h7 v1.10.4 faccfec37f82f7a1319c21638111b0f7335de7fe Include Source/Templates") ;;
    *) echo "fetch-st: unknown family '$f' (f4, g4, h7)" >&2; exit 2 ;;
    esac
done

source_of() { # $1: repository name -> a URL or a local git directory
    if [ -n "${ST_MIRROR:-}" ]; then
        for d in "$ST_MIRROR/$1" "$ST_MIRROR/$1.git"; do
            [ -d "$d" ] && { echo "$d"; return; }
        done
        echo "fetch-st: ST_MIRROR=$ST_MIRROR holds no $1 or $1.git" >&2
        return 1
    fi
    # shellcheck disable=SC2059 # the template is the format
    printf "${ST_GIT_URL:-https://github.com/STMicroelectronics/%s.git}" "$1"
}

tmp=
trap '[ -n "$tmp" ] && rm -rf "$tmp"' EXIT

# $1 name, $2 tag, $3 the commit it must be, $4 the commit found
check_commit() {
    if [ "$3" != "$4" ]; then
        echo "fetch-st: $1 $2 is commit ${4:-(none)}, not the pinned $3: refusing it" >&2
        exit 1
    fi
}

fetch_one() { # $1 name, $2 tag, $3 commit, $4... folders
    local name=$1 tag=$2 commit=$3 out=$dest/$1 src
    shift 3
    if [ -f "$out/.tag" ] && [ "$(cat "$out/.tag")" = "$tag" ]; then
        echo "fetch-st: $name $tag already in $out"
        return
    fi
    src=$(source_of "$name")
    tmp=$(mktemp -d "$dest/.fetch.XXXXXX")
    if [ -d "$src" ]; then
        check_commit "$name" "$tag" "$commit" "$(git -C "$src" rev-parse --verify -q "$tag^{commit}")"
        git -C "$src" archive --format=tar "$tag" -- "$@" | tar -x -C "$tmp"
    else
        git -c advice.detachedHead=false clone --quiet --depth 1 --branch "$tag" "$src" "$tmp/clone"
        check_commit "$name" "$tag" "$commit" "$(git -C "$tmp/clone" rev-parse HEAD)"
        (cd "$tmp/clone" && tar -c -- "$@") | tar -x -C "$tmp"
        rm -rf "$tmp/clone"
    fi
    echo "$tag" >"$tmp/.tag"
    rm -rf "$out"
    mv "$tmp" "$out"
    tmp=
    echo "fetch-st: $name $tag from $src into $out"
}

mkdir -p "$dest"
for r in "${repos[@]}"; do
    # shellcheck disable=SC2086 # "name tag commit folders..."
    fetch_one $r
done
