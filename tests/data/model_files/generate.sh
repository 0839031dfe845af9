#!/usr/bin/env bash
# Writes the model-file fixtures of tests/identify/model_file_compat_test.cpp
# with a given pneumid program, as a user would: two experiments on the
# simulated IPA rig (`pneumid simulate`), then `pneumid identify DATA -m ...
# -o FILE.json`. Run it with the program of the version the fixtures stand
# for (an older commit's build, in a separate clone), never with the current
# one: the point of the files is that an older program wrote them.
#
#   tests/data/model_files/generate.sh PNEUMID OUTDIR
#
# e.g. for the files of commit 6962d7c (README.md of the folder it writes says
# the same, with that version's commit):
#   git clone -q . /tmp/oldmain && git -C /tmp/oldmain checkout -q 6962d7c
#   cmake -S /tmp/oldmain -B /tmp/oldmain/build -DCMAKE_BUILD_TYPE=Release \
#     -DPNEUMID_BUILD_TESTS=OFF -DPNEUMID_BUILD_BENCHMARKS=OFF -DPNEUMID_BUILD_PYTHON=OFF
#   cmake --build /tmp/oldmain/build -j2 --target pneumid_cli
#   tests/data/model_files/generate.sh /tmp/oldmain/build/pneumid \
#     tests/data/model_files/v0.1.0-6962d7c
#
# OUTDIR gets the data (*.csv), the model files (DATA.GROUP.json holds models
# identified from DATA.csv: the test relies on that naming) and a README.md
# naming the program's version and commit and the commands that wrote them.
set -euo pipefail

if [[ $# -ne 2 ]]; then
  echo "usage: $0 PNEUMID OUTDIR" >&2
  exit 2
fi
pneumid=$(realpath "$1")
out=$2
[[ -x $pneumid ]] || { echo "$0: $pneumid is not an executable" >&2; exit 2; }
mkdir -p "$out"
cd "$out"

version=$("$pneumid" --version)
# The commit the program was built from, when it sits in a git checkout's build tree.
commit=$(git -C "$(dirname "$pneumid")" rev-parse --short=7 HEAD 2>/dev/null || echo unknown)

# Each step: the file it writes, '|', the arguments of pneumid ('_' stands for
# a space inside one argument: the staircase's levels). Short records keep the
# files small.
steps=(
  "step.csv|simulate --plant ipa --Ts 0.01 --input step:from=0.61,to=82,at=0.5 --duration 3 --seed 1 -o step.csv"
  "stair.csv|simulate --plant ipa --Ts 0.02 --input staircase:levels=5_25_45_65_85_95_60_30_80_10_50_15,dwell=1.2 --duration 14.4 --seed 21 -o stair.csv"
  "step.graphical.json|identify step.csv -m reaction-curve,tangent,smith,sundaresan,broida,sopdt,ptn,strejc,areas -o step.graphical.json"
  "step.process.json|identify step.csv -m fit-p1d,fit-p2d,fit-p2du,fit-p3d,fit-p1di -o step.process.json"
  "step.linear.json|identify step.csv -m arx,armax,oe,bj,iv4,n4sid -o step.linear.json"
  "stair.linear.json|identify stair.csv -m arx,armax,oe,bj,iv4,n4sid -o stair.linear.json"
  "stair.nonlinear.json|identify stair.csv -m static-map,hammerstein,wiener,hw,narx,affine-narx -o stair.nonlinear.json"
)
table=""
for step in "${steps[@]}"; do
  file=${step%%|*}
  read -r -a args <<<"${step#*|}"
  args=("${args[@]//_/ }")
  echo "pneumid ${args[*]}" >&2
  rm -f "$file"
  # identify writes the models that succeeded and names the failed methods on
  # stderr: a fixture must hold every method it names
  if ! "$pneumid" "${args[@]}" 2>stderr.txt >/dev/null || grep -q ' failed: ' stderr.txt; then
    cat stderr.txt >&2
    rm -f stderr.txt
    echo "$0: pneumid ${args[*]} failed" >&2
    exit 1
  fi
  cat stderr.txt >&2
  rm -f stderr.txt
  shown=pneumid
  for a in "${args[@]}"; do [[ $a == *" "* ]] && shown+=" '$a'" || shown+=" $a"; done
  table+="| ${file} | \`${shown}\` |"$'\n'
done

cat >README.md <<EOF
# Model files of pneumid ${version}

Written by pneumid ${version} (\`pneumid --version\`), built from commit ${commit},
with [../generate.sh](../generate.sh): \`pneumid simulate\` wrote the data and
\`pneumid identify DATA -m ... -o FILE.json\` the models, as a user would. Do
not edit them by hand: tests/identify/model_file_compat_test.cpp checks that
the current library loads every model of every file, writes it back
unchanged and simulates it on its data to the fit the file states.

A file DATA.GROUP.json holds models identified from DATA.csv.

| file | written by |
| --- | --- |
${table}
To regenerate them, build that commit's program in a separate clone and run
the script with it (from the repository root):

\`\`\`sh
git clone -q . /tmp/oldmain && git -C /tmp/oldmain checkout -q ${commit}
cmake -S /tmp/oldmain -B /tmp/oldmain/build -DCMAKE_BUILD_TYPE=Release \\
  -DPNEUMID_BUILD_TESTS=OFF -DPNEUMID_BUILD_BENCHMARKS=OFF -DPNEUMID_BUILD_PYTHON=OFF
cmake --build /tmp/oldmain/build -j2 --target pneumid_cli
tests/data/model_files/generate.sh /tmp/oldmain/build/pneumid tests/data/model_files/$(basename "$PWD")
\`\`\`
EOF
ls -l
