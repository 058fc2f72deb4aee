#!/usr/bin/env bash
# Rewrites citations of documents outside the repository into their in-repository homes:
#   physics.md §N (and reference/physics.md)      → docs/physics.md §N
#   shared/reference/X.csv, ../shared/reference/X.csv, reference/X.csv → data/reference/X.csv
#   the ASTM E308 weights CSV                     → `WEIGHTS_D65` in crates/optics/src/colour.rs
#   "see reference/ for formulas"                 → see docs/physics.md
#   STYLE.md (the style brief)                    → ARCHITECTURE.md, "Code conventions"
#   DESIGN.md (the design brief)                  → "the design brief" where it is history,
#                                                   ARCHITECTURE.md where it is a reference
# Idempotent: a second run changes nothing. `crates/optics/tests/citations.rs` checks the result.
#
# Usage: scripts/fix_citations.sh [--skip PATH]... [--dry-run]
#   Runs over every tracked .rs, .md and .toml file (git ls-files), except the ones given with
#   --skip (paths relative to the repository root). --dry-run lists the files it would change.
set -euo pipefail

cd "$(git rev-parse --show-toplevel)"

skip=()
dry_run=0
while [ $# -gt 0 ]; do
    case "$1" in
        --skip) skip+=("$2"); shift 2 ;;
        --dry-run) dry_run=1; shift ;;
        -h|--help) sed -n '2,17p' "$0"; exit 0 ;;
        *) echo "fix_citations.sh: unknown argument $1 (see --help)" >&2; exit 2 ;;
    esac
done

# One sed program; the order matters (specific forms before general ones).
program=$(cat <<'SED'
s#`(\.\./)?(shared/)?reference/astm_e308_weights_10nm\.csv`#`WEIGHTS_D65` in `crates/optics/src/colour.rs`#g
s#(\.\./)?(shared/)?reference/astm_e308_weights_10nm\.csv#`WEIGHTS_D65` in crates/optics/src/colour.rs#g
s#(\.\./)?shared/reference/physics\.md#docs/physics.md#g
s#(^|[^/A-Za-z_])reference/physics\.md#\1docs/physics.md#g
s#(\.\./)?shared/reference/([A-Za-z0-9_]+\.csv)#data/reference/\2#g
s#(^|[^/A-Za-z_])reference/([A-Za-z0-9_]+\.csv)#\1data/reference/\2#g
s#see reference/ for formulas#see docs/physics.md for formulas#g
s#(^|[^/A-Za-z_])physics\.md#\1docs/physics.md#g
s#\[STYLE\.md\]#ARCHITECTURE.md, "Code conventions"#g
s#STYLE\.md#ARCHITECTURE.md, "Code conventions"#g
s#the design brief \(DESIGN\.md\)#the design brief#g
s#DESIGN\.md's#the design brief's#g
s#as DESIGN\.md asks#as the design brief asked#g
s#DESIGN\.md#ARCHITECTURE.md#g
SED
)

is_skipped() {
    local f=$1 s
    for s in "${skip[@]+"${skip[@]}"}"; do
        [ "$f" = "$s" ] && return 0
    done
    return 1
}

changed=0
while IFS= read -r -d '' file; do
    is_skipped "$file" && continue
    [ -f "$file" ] || continue
    if ! sed -E "$program" "$file" | cmp -s - "$file"; then
        changed=$((changed + 1))
        if [ "$dry_run" = 1 ]; then
            echo "would change $file"
        else
            sed -E -i "$program" "$file"
            echo "changed $file"
        fi
    fi
done < <(git ls-files -z -- '*.rs' '*.md' '*.toml')

echo "fix_citations.sh: $changed file(s) $([ "$dry_run" = 1 ] && echo 'to change' || echo 'changed')"
