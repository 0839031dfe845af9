#!/usr/bin/env bash
# CLI test of `pneumid impulse`: the impulse response of the paper's FOPDT
# against its closed form g(t) = K/tau exp(-(t - theta)/tau) for t > theta
# (peak K/tau at theta, area K, 2 % settling at theta + tau ln 50), the area of
# a discrete model (its DC gain), --plot, and errors.
# Usage: bash impulse_test.sh /path/to/pneumid
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"

check_help impulse --model --num --den --Ts --t-final --plot --json

# K = 1.6, tau = 0.245 s, theta = 0.001 s; dt = tau/200 on the default grid:
# times within one sample, amplitudes within 1 % (one sample of decay).
expect_ok "fopdt" impulse --model fopdt-paper --json
check_json "keys" "all(k in j for k in ['peak', 'peak_time', 'settling_time', 'area', 'stable', 't', 'y'])"
check_json "peak" "abs(j['peak'] / (1.6 / 0.245) - 1) < 0.01"
check_json "peak time" "abs(j['peak_time'] - 0.001) <= 0.245 / 200"
check_json "settling" "abs(j['settling_time'] - (0.001 + 0.245 * 3.9120230054)) <= 0.245 / 200"
check_json "area" "abs(j['area'] / 1.6 - 1) < 0.01 and j['stable'] is True"
check_json "samples" "len(j['t']) == len(j['y']) and j['t'][0] == 0"

# Discrete: the paper's ARX model (Eq. 5); the area of its response is its DC gain.
expect_ok "arx" impulse --model arx-paper --t-final 3 --json
check_json "arx area" "abs(j['area'] / 1.59796 - 1) < 0.01"
check_json "arx grid" "abs(j['t'][1] - 0.01) < 1e-12"

# Text output.
expect_ok "text" impulse --num 1 --den 1,2,1
check_output "text" "peak_time"
check_output "text area" "area"

# Unstable: no area, no settling time, exit 0 with a note.
expect_ok "unstable" impulse --num 1 --den 1,-1 --t-final 2 --json
check_json "unstable" "j['stable'] is False and j['area'] is None and j['settling_time'] is None"
expect_ok "unstable text" impulse --num 1 --den 1,-1 --t-final 2
check_output "unstable text" "not stable"

# --plot.
expect_ok "plot png" impulse --model fopdt-paper --plot "$TMP/impulse.png"
check_png "$TMP/impulse.png"
check_output "plot png" "plot written to $TMP/impulse.png"
expect_ok "plot svg" impulse --model arx-paper --plot "$TMP/impulse.svg"
check_svg "$TMP/impulse.svg"
check_output "svg title" "Impulse response of arx-paper" "$TMP/impulse.svg"

# Errors.
expect_error "no model" "give a model" impulse
expect_error "bad tfinal" "--t-final: must be >= 0, got -1" impulse --model fopdt-paper --t-final -1
expect_error "bad threshold" "--settling-threshold: must be in [0, 1], got 2" impulse --model fopdt-paper --settling-threshold 2
expect_error "plot extension" "must end in .png or .svg" impulse --model fopdt-paper --plot "$TMP/i.gif"
finish
