#!/usr/bin/env python3
"""Independent check of the sentences tracker-host sends to chart plotters (TTM, TLL, own
ship's RMC/HDT/OSD), with pynmea2: every sentence parses with a valid checksum, every TLL
position is where the `# expect OWN_LAT OWN_LON RANGE_M BEARING_DEG` line after it says: at
that range and bearing from own ship on the WGS84 ellipsoid, by Karney's geodesics in
geographiclib (within 1e-6 degrees, a decimetre), bearings and courses are within
0-359.9 (a course may be empty: a target whose motion is not known yet).

Usage: check_nmea.py FILE    (exit 0 when every sentence passes)
"""
import sys

import pynmea2
from geographiclib.geodesic import Geodesic


def position(tll):
    """Degrees from a TLL's ddmm.mmmmm,N / dddmm.mmmmm,E fields."""
    lat = int(tll.lat[:2]) + float(tll.lat[2:]) / 60.0
    lon = int(tll.lon[:3]) + float(tll.lon[3:]) / 60.0
    if len(tll.lat.split(".")[0]) != 4 or len(tll.lon.split(".")[0]) != 5:
        sys.exit(f"TLL degrees not 2 and 3 digits: {tll}")
    if tll.lat_dir not in "NS" or tll.lon_dir not in "EW":
        sys.exit(f"TLL hemispheres: {tll}")
    return (lat if tll.lat_dir == "N" else -lat, lon if tll.lon_dir == "E" else -lon)


def main(path):
    last_tll = None
    checked = 0
    with open(path) as f:
        for n, line in enumerate(f, 1):
            line = line.strip()
            if not line:
                continue
            if line.startswith("# expect"):
                own_lat, own_lon, range_m, bearing = map(float, line.split()[2:6])
                if last_tll is None:
                    sys.exit(f"line {n}: an expectation without a TLL")
                at = Geodesic.WGS84.Direct(own_lat, own_lon, bearing, range_m)
                lat, lon = at["lat2"], (at["lon2"] + 180.0) % 360.0 - 180.0
                got = position(last_tll)
                if abs(got[0] - lat) > 1e-6 or abs((got[1] - lon + 180.0) % 360.0 - 180.0) > 1e-6:
                    sys.exit(f"line {n}: TLL at {got}, expected {(lat, lon)}")
                continue
            msg = pynmea2.parse(line, check=True)
            kind = msg.sentence_type
            if kind == "TTM":
                # A target whose motion is not known yet (acquiring, Q; a failed acquisition's
                # L) goes with its course empty, as IEC 61162-1 sends a value not available.
                if msg.bearing in (None, ""):
                    sys.exit(f"line {n}: no bearing: {line}")
                angles = [msg.bearing] + ([] if msg.cog in (None, "") else [msg.cog])
                for field in angles:
                    if not 0.0 <= float(field) < 360.0:
                        sys.exit(f"line {n}: angle {field} out of 0-359.9: {line}")
            elif kind == "TLL":
                lat, lon = position(msg)
                if not (-90 <= lat <= 90 and -180 <= lon <= 180):
                    sys.exit(f"line {n}: position out of range: {line}")
                last_tll = msg
            elif kind in ("RMC", "HDT", "OSD"):
                pass
            else:
                sys.exit(f"line {n}: unexpected {kind}: {line}")
            checked += 1
    print(f"{checked} sentences checked with pynmea2 {pynmea2.version}")


if __name__ == "__main__":
    main(sys.argv[1])
