#!/usr/bin/env python3
"""Write an opencpn.conf for the check: patch the template OpenCPN 5.10.2 wrote on
its first run (so no first-run wizard), adding the TCP data connection, the
viewport and AIS/ARPA display options.
usage: make_conf.py TEMPLATE OUT LAT LON PORT WIDTH_NM"""
import math, re, sys
tmpl, out, lat, lon, port, width_nm = sys.argv[1], sys.argv[2], float(sys.argv[3]), float(sys.argv[4]), int(sys.argv[5]), float(sys.argv[6])
text = open(tmpl).read()
# OpenCPN's VPScale is screen pixels per metre of its (equator-scaled) Mercator plane,
# so a true ground distance at latitude lat is stretched by 1/cos(lat).
canvas_px = 1598
scale = canvas_px * math.cos(math.radians(lat)) / (width_nm * 1852.0)
sets = {
    # section -> {key: value}
    'Settings': {'OpenGL': '0', 'ShowMenuBar': '1', 'ShowStatusBar': '1'},
    'Settings/GlobalState': {
        'OwnShipLatLon': f'"{lat:.4f},{lon:.4f}"',
        'FrameMax': '0', 'FrameWinX': '1600', 'FrameWinY': '1000',
        'FrameWinPosX': '0', 'FrameWinPosY': '0',
        'ClientPosX': '0', 'ClientPosY': '0', 'ClientSzX': '1600', 'ClientSzY': '1000',
    },
    'Settings/AIS': {
        'bCPAWarn': '1', 'CPAWarnNMi': '0.5', 'bTCPAMax': '1', 'TCPAMaxMinutes': '30',
        'bShowCOGArrows': '1', 'CogArrowMinutes': '6',
        'bShowTargetTracks': '1', 'TargetTracksMinutes': '5',
        'bShowAISName': '1', 'ShowAISTargetNameScale': '500000',
        'bAISAlertDialog': '0', 'bAISAlertAudio': '0',
        'bAISRolloverShowCPA': '1', 'bAISRolloverShowCOG': '1',
        'bMarkLostTargets': '1', 'MarkLost_Minutes': '8',
        'bRemoveLostTargets': '1', 'RemoveLost_Minutes': '10',
    },
    'Settings/NMEADataSource': {
        # type;netproto;addr;port;dataproto;serialport;baud;checksum;direction(0=in);
        # inListType;inList;outListType;outList;priority;garmin;garminUpload;furuno;
        # enabled;comment;autoSK;socketCAN;noDataReconnect;disableEcho
        'DataConnections': f'1;0;127.0.0.1;{port};0;;4800;1;0;0;;0;;0;0;0;0;1;tracker-host;0;;0;0',
    },
    'Canvas/CanvasConfig1': {
        'canvasVPLatLon': f'"{lat:.4f},{lon:.4f}"',
        'canvasVPScale': f'{scale:.5f}',
        'canvasbFollow': '0', 'canvasShowGrid': '1', 'canvasShowAIS': '1',
        'canvasSizeX': '1598', 'canvasSizeY': '950',
    },
}
lines = text.splitlines()
section = None
seen = {s: set() for s in sets}
outl = []
def flush(sec):
    if sec in sets:
        for k, v in sets[sec].items():
            if k not in seen[sec]:
                outl.append(f'{k}={v}')
for ln in lines:
    m = re.match(r'^\[(.*)\]$', ln)
    if m:
        flush(section)
        section = m.group(1)
        outl.append(ln)
        continue
    if section in sets and '=' in ln:
        k = ln.split('=', 1)[0]
        if k in sets[section]:
            outl.append(f'{k}={sets[section][k]}')
            seen[section].add(k)
            continue
    outl.append(ln)
flush(section)
open(out, 'w').write('\n'.join(outl) + '\n')
print(f'VPScale={scale:.5f} for {width_nm} NM across {canvas_px} px at lat {lat}')
