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
# "name tag folders...": only these folders are kept.
repos=("cmsis_core v5.9.0 Include")
for f in "${families[@]}"; do
    case $f in
    f4) repos+=("stm32f4xx_hal_driver v1.8.3 Inc Src" "cmsis_device_f4 v2.6.9 Include Source/Templates") ;;
    g4) repos+=("stm32g4xx_hal_driver v1.2.4 Inc Src" "cmsis_device_g4 v1.2.4 Include Source/Templates") ;;
    h7) repos+=("stm32h7xx_hal_driver v1.11.3 Inc Src" "cmsis_device_h7 v1.10.4 Include Source/Templates") ;;
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

fetch_one() { # $1 name, $2 tag, $3... folders
    local name=$1 tag=$2 out=$dest/$1 src
    shift 2
    if [ -f "$out/.tag" ] && [ "$(cat "$out/.tag")" = "$tag" ]; then
        echo "fetch-st: $name $tag already in $out"
        return
    fi
    src=$(source_of "$name")
    tmp=$(mktemp -d "$dest/.fetch.XXXXXX")
    if [ -d "$src" ]; then
        git -C "$src" archive --format=tar "$tag" -- "$@" | tar -x -C "$tmp"
    else
        git -c advice.detachedHead=false clone --quiet --depth 1 --branch "$tag" "$src" "$tmp/clone"
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
    # shellcheck disable=SC2086 # "name tag"
    fetch_one $r
done
