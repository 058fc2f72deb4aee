#!/bin/bash
# A real camera's effects on the quick twin: σ′s, σa errors with and without each handling (model mc).
B=${SCATTERFIT:-$(cd "$(dirname "$0")/.." && pwd)/target/debug/scatterfit}
M=${MAT:-wood-tile}
W=${1:-/tmp/scatterfit-camera-effects}; mkdir -p "$W"; cd "$W"
err() { # dir
python3 - "$1" <<'PY'
import json,sys
d=sys.argv[1]
t=json.load(open(d+'/truth.json'))
try:
  r=json.load(open(d+'/out/result.json'))
except Exception as e:
  print("no result"); sys.exit()
out=[]
for i,c in enumerate("rgb"):
  ch=r["channels"][c]; tc=t["channels"][i]
  sp=(ch.get("sigma_s_prime") or {}).get("value"); sa=(ch.get("sigma_a") or {}).get("value")
  if sp is None: out.append(f"{c.upper()}: –"); continue
  out.append(f"{c.upper()} {100*(sp/tc['sigma_s_prime']-1):+.1f}/{100*(sa/tc['sigma_a']-1):+.1f}")
print("  ".join(out))
PY
}
run() { # name synth-args key-lines-without
  name=$1; shift; sargs=$1; shift; without=$1
  rm -rf $name; $B synth --material $M --quick --quiet -o $name $sargs > /dev/null || { echo "$name: synth failed"; return; }
  $B measure $name -o $name/out --model mc > $name/with.txt 2>&1; echo "$name with:    $(err $name) (exit $?)"
  cp $name/sample.toml $name/sample.with.toml
  python3 - $name "$without" <<'PY'
import sys,re
d,w=sys.argv[1],sys.argv[2]
s=open(d+'/sample.toml').read()
for kv in w.split(';'):
  kv=kv.strip()
  if not kv: continue
  if kv.startswith('-'):
    key=kv[1:]; s=re.sub(r'(?m)^'+key+r'\s*=.*\n','',s)
  else:
    s=s.replace('[camera]\n','[camera]\n'+kv+'\n',1)
open(d+'/sample.toml','w').write(s)
PY
  rm -rf $name/out; $B measure $name -o $name/out --model mc > $name/without.txt 2>&1; echo "$name without: $(err $name)"
  mv $name/sample.with.toml $name/sample.toml
}
run base "" ""
run glare "--glare 3e-4" 'background = "none"'
run black "--camera linear16" 'black_level = "none"'
run vignetting "--vignetting 0.3" '-flat'
run exposure "--exposure-error 0.03" 'exposure_correction = "never"'
run gaussian "--gaussian-spot" '-spot_profile'
run spotimage "--gaussian-spot --spot-image" '-spot_image'
run dng "--camera dng" 'black_level = "none"'
