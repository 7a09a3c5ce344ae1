#!/bin/sh
# Regenerates schemas/generatedSchema.usda and plugInfo/plugInfo.json from
# schemas/schema.usda with usdGenSchema (codeless: no C++ is generated).
#
#   . .venv/bin/activate && pip install jinja2   # usdGenSchema needs jinja2
#   sh schemas/generate.sh
#
# usdGenSchema writes both files into one directory, so it runs in a scratch
# directory seeded with the current plugInfo.json (its Name/Root/ResourcePath
# survive regeneration; only the "Types" entries are rewritten).
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
python=${PYTHON:-python}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cp "$root/plugInfo/plugInfo.json" "$tmp/plugInfo.json"
# Our own (old) registration must not take part in the generation.
env -u PXR_PLUGINPATH_NAME "$python" -m pxr.Usd.usdGenSchema -q \
    "$here/schema.usda" "$tmp"
cp "$tmp/generatedSchema.usda" "$here/generatedSchema.usda"
cp "$tmp/plugInfo.json" "$root/plugInfo/plugInfo.json"
echo "wrote $here/generatedSchema.usda and $root/plugInfo/plugInfo.json"
