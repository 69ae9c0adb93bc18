#!/bin/sh
# Installs Sake Glug from this folder, or removes what it installed.
#
#   ./install.sh [--prefix DIR] [--clap-dir DIR] [--vst3-dir DIR]
#   ./install.sh --uninstall [--prefix DIR]
#
# bin/, lib/, include/ and share/ go under the prefix (~/.local unless told), the CLAP plugin
# into ~/.clap and the VST3 plugin into ~/.vst3, where hosts look for a user's plugins. Every
# file and folder it makes is listed in PREFIX/share/sake-glug/installed-files, and
# --uninstall removes exactly those (a folder only if nothing else is left in it). Installing
# again first removes what the last install put there.
set -eu

prefix="$HOME/.local"
clap_dir="$HOME/.clap"
vst3_dir="$HOME/.vst3"
uninstall=no
usage="usage: $0 [--prefix DIR] [--clap-dir DIR] [--vst3-dir DIR] | --uninstall [--prefix DIR]"

while [ $# -gt 0 ]; do
    case "$1" in
        --prefix) [ $# -ge 2 ] || { echo "$usage" >&2; exit 2; }; prefix=$2; shift 2 ;;
        --clap-dir) [ $# -ge 2 ] || { echo "$usage" >&2; exit 2; }; clap_dir=$2; shift 2 ;;
        --vst3-dir) [ $# -ge 2 ] || { echo "$usage" >&2; exit 2; }; vst3_dir=$2; shift 2 ;;
        --uninstall) uninstall=yes; shift ;;
        -h|--help) echo "$usage"; exit 0 ;;
        *) echo "$0: unknown option '$1'" >&2; echo "$usage" >&2; exit 2 ;;
    esac
done

manifest="$prefix/share/sake-glug/installed-files"

remove_installed() {
    # Files first, then folders deepest first; a folder that holds anything else stays. The
    # folders are read before the files go, their list among them.
    folders=$(grep '^d ' "$manifest.folders" 2>/dev/null | cut -c3- | sort -r || true)
    grep '^f ' "$manifest" | cut -c3- | while IFS= read -r path; do
        rm -f "$path"
    done
    printf '%s\n' "$folders" | while IFS= read -r path; do
        [ -z "$path" ] || rmdir "$path" 2>/dev/null || true
    done
}

if [ "$uninstall" = yes ]; then
    if [ ! -f "$manifest" ]; then
        echo "$0: nothing to uninstall: $manifest does not exist" >&2
        exit 1
    fi
    remove_installed
    echo "Sake Glug removed: every file that install.sh had put under $prefix and in the plugin folders"
    exit 0
fi

here=$(cd "$(dirname "$0")" && pwd)
list=$(mktemp)
trap 'rm -f "$list"' EXIT

# Makes folder $1 and the missing ones above it, listing each one it made.
make_folder() {
    if [ ! -d "$1" ]; then
        make_folder "$(dirname "$1")"
        mkdir "$1"
        echo "d $1" >>"$list"
    fi
}

# Copies the tree $1 (relative to this folder) into $2, keeping symbolic links as links.
copy_tree() {
    (cd "$here/$1" && find . -type f -o -type l) | sort | while IFS= read -r file; do
        file=${file#./}
        make_folder "$(dirname "$2/$file")"
        rm -f "$2/$file"
        cp -P "$here/$1/$file" "$2/$file"
        echo "f $2/$file" >>"$list"
    done
}

if [ -f "$manifest" ]; then
    remove_installed
fi
for folder in bin lib include share; do
    copy_tree "$folder" "$prefix/$folder"
done
copy_tree clap "$clap_dir"
copy_tree vst3 "$vst3_dir"
make_folder "$prefix/share/sake-glug"
# Files and folders apart: removing files may empty folders listed before them.
grep '^f ' "$list" >"$manifest"
echo "f $manifest" >>"$manifest"
echo "f $manifest.folders" >>"$manifest"
grep '^d ' "$list" >"$manifest.folders" || true

echo "Sake Glug installed: $prefix/bin/sake-glug, the C library in $prefix/lib (pkg-config:"
echo "PKG_CONFIG_PATH=$prefix/lib/pkgconfig), the plugins in $clap_dir and $vst3_dir."
echo "Remove it with: $0 --uninstall --prefix $prefix"
