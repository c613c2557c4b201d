#!/bin/sh
# `demmat scene --contact KEY=VALUE` writes the [contact] table, `demmat run` prints the law it runs and
# the model picked carries its flags, and a saved state of a law with memory continues (docs/scene-format.md).
# usage: check_contact_law_cli.sh DEMMAT WORKDIR
set -eu
demmat=$1
work=$2
rm -rf "$work" && mkdir -p "$work"
"$demmat" scene drop --contact tangential=linear_history --contact kt=50 --contact tangential_damping_ratio=0.5 \
    --contact damping=restitution --contact restitution=0.7 -o "$work/drop.toml"
grep -q '^tangential = "linear_history"$' "$work/drop.toml"
grep -q '^restitution = 0.7$' "$work/drop.toml"
"$demmat" run "$work/drop.toml" --steps 20000 -q --save "$work/drop.state" > "$work/run.txt"
grep -q '^contact law damping restitution (restitution = 0.7), tangential linear_history (kt = 50 N/m, tangential_damping_ratio = 0.5), rolling none; η_n = α·sqrt(m\*·k_n) with α = ' "$work/run.txt"
grep -q '^model .*restitution_damping+history' "$work/run.txt"
# The sphere rests on the wall after 0.2 s: the state holds its one wall contact's stretch (version 2).
[ "$(od -An -tu4 -j8 -N4 "$work/drop.state" | tr -d ' ')" = 2 ]
# A scene continuing that state keeps the law (compression: a stage that starts from a state).
"$demmat" scene compression --from "$work/drop.toml" --state "$work/drop.state" -o "$work/cont.toml"
grep -q '^tangential = "linear_history"$' "$work/cont.toml"
"$demmat" run "$work/cont.toml" --steps 100 -q > /dev/null
# The paper's law writes no table.
"$demmat" scene drop -o "$work/paper.toml"
if grep -q "^\[contact\]" "$work/paper.toml"; then echo "the paper's law wrote a [contact] table"; exit 1; fi
echo ok
