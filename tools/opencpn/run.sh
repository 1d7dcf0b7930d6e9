#!/bin/bash
# End-to-end check of tracker-host's NMEA 0183 output in OpenCPN 5.10 (headless, Xvfb): a
# tool beside the product, not part of it (root, apt, several minutes).
#
#   tools/opencpn/run.sh [solent|sydney|LAT,LON] [TAG]
#
# Uses target/release/tracker-host (TRACKER_HOST overrides); writes to $OUT (default
# /tmp/opencpn-check).
#
# Env: CHART_LAT, CHART_LON (the chart's centre; default the origin), PORT (default 10110; if that port is taken, the next free one from 10111 is used),
#      WAIT1 (s before the first screenshot, default 75), WAIT2 (s to the second, default 60),
#      WIDTH_NM (chart width in NM, default 12), DISP (X display number, default 99),
#      MINIMAL_CONF=1 to write a from-scratch opencpn.conf instead of patching the template,
#      DEMO_ARGS to run another picture (default "--duration 900"; e.g. real Solent traffic:
#      "--ais-truth ../shared/realdata/ais/stonesoup-SolentAIS_20160112_130211.csv --own-mmsi 234586000").
#      TRACK_ARGS to run `track` instead of the demo (e.g. "--radar pcap:../shared/realdata/radar/radar_pi-3g-trueheading.pcap.gz --speedup 0.1"),
#      PYTHON (default python3; .venv/bin/python has geographiclib for the TTM/TLL check).
# Leaves in /tmp/opencpn-check: TAG-1.png, TAG-2.png (a minute later), TAG-list.png (AIS
# target list sorted by range), TAG-overview.png (zoomed out x2), TAG-nmea.txt (the stream
# as a second TCP client saw it), TAG-analysis.txt, TAG-tracker.out, TAG-opencpn.log.
# Everything is written under /tmp/opencpn-check (OpenCPN runs with HOME=/tmp/opencpn-check/home-TAG).
set -uo pipefail
TOOLS=$(cd "$(dirname "$0")" && pwd)
# The tracker runs where this was started, so that DEMO_ARGS' relative paths (the README's
# ../shared/...) mean what they meant there.
CALLER=$PWD
TRACKER_HOST=$(realpath -m "${TRACKER_HOST:-$TOOLS/../../target/release/tracker-host}")
PYTHON=$(command -v "${PYTHON:-python3}" || echo python3)
case "$PYTHON" in /*) ;; *) PYTHON=$(realpath -m "$PYTHON") ;; esac
D=${OUT:-/tmp/opencpn-check}
mkdir -p "$D"
cd "$D"
WHERE=${1:-solent}
case "$WHERE" in
  solent) LAT=50.6667; LON=-1.0; ORIGIN_ARG=() ;;              # the tracker's default origin
  sydney) LAT=-33.9;  LON=151.2; ORIGIN_ARG=(--origin -33.9,151.2) ;;
  *,*)    LAT=${WHERE%,*}; LON=${WHERE#*,}; ORIGIN_ARG=(--origin "$WHERE") ;;
  *) echo "usage: $0 [solent|sydney|LAT,LON] [TAG]"; exit 2 ;;
esac
TAG=${2:-$WHERE}; TAG=${TAG//[^A-Za-z0-9_-]/_}
# The chart's centre: the origin unless told (own ship may start elsewhere, e.g. in
# Portsmouth Harbour with --own-mmsi 234586000: CHART_LAT=50.8015 CHART_LON=-1.1119).
CHART_LAT=${CHART_LAT:-$LAT}; CHART_LON=${CHART_LON:-$LON}
WAIT1=${WAIT1:-75}; WAIT2=${WAIT2:-60}; WIDTH_NM=${WIDTH_NM:-12}; DISP=${DISP:-99}
export DISPLAY=:$DISP

# 1. OpenCPN 5.10 from bookworm-backports, plus Xvfb and screenshot tools (root).
if ! dpkg-query -W -f='${Version}' opencpn 2>/dev/null | grep -q '5\.10'; then
  grep -rqs 'bookworm-backports' /etc/apt/sources.list /etc/apt/sources.list.d/ ||
    echo 'deb http://deb.debian.org/debian bookworm-backports main' > /etc/apt/sources.list.d/backports.list
  apt-get update
  DEBIAN_FRONTEND=noninteractive apt-get install -y -t bookworm-backports opencpn
fi
for p in xvfb x11-apps x11-utils imagemagick xdotool; do
  dpkg -s $p >/dev/null 2>&1 || DEBIAN_FRONTEND=noninteractive apt-get install -y $p
done
echo "OpenCPN package: $(dpkg-query -W -f='${Version}' opencpn)"
[ -x "$TRACKER_HOST" ] || { echo "no $TRACKER_HOST: cargo build --release -p tracker-host"; exit 1; }

# 2. A free port (someone else may already serve 10110).
PORT=${PORT:-10110}
port_busy() { ss -ltnH "sport = :$1" | grep -q .; }
if port_busy "$PORT"; then
  echo "port $PORT is in use (not ours); looking for a free one"
  PORT=10111; while port_busy $PORT; do PORT=$((PORT+1)); done
fi
echo "tracker NMEA port: $PORT"

# 3. OpenCPN config: TCP client to 127.0.0.1:$PORT, chart centred on the origin, AIS/ARPA options.
H="$D/home-$TAG"; rm -rf "$H"; mkdir -p "$H/.opencpn"
if [ "${MINIMAL_CONF:-0}" = 1 ] || [ ! -f "$D/opencpn.conf.template" ]; then
  printf '[Settings]\nNavMessageShown=1\n[Settings/GlobalState]\n[Settings/AIS]\n[Settings/NMEADataSource]\n[Canvas]\nCanvasConfig=0\n[Canvas/CanvasConfig1]\n' > "$H/tmpl.conf"
  python3 "$TOOLS/make_conf.py" "$H/tmpl.conf" "$H/.opencpn/opencpn.conf" "$CHART_LAT" "$CHART_LON" "$PORT" "$WIDTH_NM"
else
  python3 "$TOOLS/make_conf.py" "$D/opencpn.conf.template" "$H/.opencpn/opencpn.conf" "$CHART_LAT" "$CHART_LON" "$PORT" "$WIDTH_NM"
fi
grep -E '^(DataConnections|canvasVPLatLon|canvasVPScale|OwnShipLatLon)=' "$H/.opencpn/opencpn.conf"

PIDS=()
cleanup() { for p in "${PIDS[@]}"; do kill -TERM "$p" 2>/dev/null; done; sleep 3;
            for p in "${PIDS[@]}"; do kill -KILL "$p" 2>/dev/null; done; }
trap cleanup EXIT

# 4. Xvfb (reuse one already on :$DISP), tracker, a recording second client, OpenCPN.
if ! xdpyinfo >/dev/null 2>&1; then
  Xvfb :$DISP -screen 0 1600x1000x24 -nolisten tcp > "$D/$TAG-xvfb.log" 2>&1 & PIDS+=($!)
  sleep 2
fi
# DEMO_ARGS replaces the demo's own arguments (e.g. "--ais-truth FILE --own-mmsi N");
# TRACK_ARGS runs `track` with them instead of the demo (e.g. "--radar pcap:CAPTURE
# --speedup 0.1": a capture's few seconds, slowed, since OpenCPN takes about 10 s to connect).
if [ -n "${TRACK_ARGS:-}" ]; then
  read -r -a ARGS <<< "$TRACK_ARGS"
  COMMAND=(track --plain "${ARGS[@]}")
else
  read -r -a DEMO <<< "${DEMO_ARGS:---duration 900}"
  COMMAND=(demo --plain --speedup 1 "${DEMO[@]}")
fi
(cd "$CALLER" && exec "$TRACKER_HOST" --link inproc "${COMMAND[@]}" \
  --nmea-out tcp:$PORT --nmea-out-own-ship "${ORIGIN_ARG[@]}") > "$D/$TAG-tracker.out" 2>&1 & TRACKER=$!; PIDS+=($TRACKER)
sleep 2
tracker_alive() {
  kill -0 "$TRACKER" 2>/dev/null && return
  echo "tracker-host stopped:"; cat "$D/$TAG-tracker.out"; exit 1
}
tracker_alive
python3 "$TOOLS/nmea_tap.py" 127.0.0.1 $PORT "$D/$TAG-nmea.txt" $((WAIT1 + WAIT2 + 60)) & PIDS+=($!)
HOME="$H" opencpn > "$D/$TAG-opencpn.out" 2>&1 & OCPN=$!; PIDS+=($OCPN)

dismiss_dialogs() {
  # "Welcome to OpenCPN .. Version x" is the nav-warning (OK = agree, Cancel = QUIT): click its OK.
  # Anything else unexpected: focus it and press Escape.
  for w in $(xdotool search --onlyvisible --name '.+' 2>/dev/null); do
    n=$(xdotool getwindowname "$w")
    case "$n" in
      "OpenCPN 5"*|"AIS target list"|"NMEA Debug Window"|"") ;;
      "Welcome to OpenCPN"*)
        eval "$(xdotool getwindowgeometry --shell "$w")"
        echo "accepting nav warning: $n"; xdotool mousemove $((X + WIDTH - 66)) $((Y + HEIGHT - 29)) click 1 ;;
      *) echo "dismissing dialog: $n"; xdotool windowfocus "$w" 2>/dev/null; xdotool key Escape ;;
    esac
  done
}
for i in $(seq 1 30); do sleep 1; dismiss_dialogs; done   # the nav warning blocks the data connection
sleep $((WAIT1 > 30 ? WAIT1 - 30 : 0)); dismiss_dialogs; tracker_alive
import -window root "$D/$TAG-1.png"; echo "screenshot $D/$TAG-1.png at $(date -u +%T)"
sleep "$WAIT2"; dismiss_dialogs; tracker_alive
import -window root "$D/$TAG-2.png"; echo "screenshot $D/$TAG-2.png at $(date -u +%T)"

# 5. AIS target list: menu AIS > "AIS target list...", enlarge it so CPA/TCPA show, sort by range.
xdotool mousemove 140 12 click 1; sleep 1.5; xdotool mousemove 200 214 click 1; sleep 4
W=$(xdotool search --onlyvisible --name '^AIS target list$' | head -1)
if [ -n "$W" ]; then
  xdotool windowsize "$W" 1560 940; xdotool windowmove "$W" 20 40; sleep 2; xdotool windowraise "$W"; sleep 1
  xdotool mousemove 606 72 click 1; sleep 3   # "Range" column header
  import -window root "$D/$TAG-list.png"; echo "screenshot $D/$TAG-list.png at $(date -u +%T)"
  xdotool windowunmap "$W"
else
  echo "AIS target list did not open"
fi
# 6. Zoomed out once (all targets out to ~12 NM).
xdotool mousemove 1403 950 click 1; sleep 4
import -window root "$D/$TAG-overview.png"; echo "screenshot $D/$TAG-overview.png at $(date -u +%T)"

# 7. Quit OpenCPN cleanly (SIGTERM), keep its log, check the recorded stream.
kill -TERM $OCPN; sleep 6
cp "$H/.opencpn/opencpn.log" "$D/$TAG-opencpn.log"
echo "--- OpenCPN log: connection and errors"
grep -E 'MakeCommDriver|NetworkDataStream|TCP Server|comm_drv|rror|WARN' "$D/$TAG-opencpn.log" | grep -v -E 'ENCShow|mmsitoname|navobj' || true
"$PYTHON" "$TOOLS/analyze_nmea.py" "$D/$TAG-nmea.txt" | tee "$D/$TAG-analysis.txt"
