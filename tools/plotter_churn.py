#!/usr/bin/env python3
"""Counts what a chart plotter sees of the tracker's targets: listens on a UDP port for the
`--nmea-out udp:127.0.0.1:PORT` stream and prints the TTM reports sent as tracked or
acquiring (T/Q), the ends (L), and the ends whose number was sent again after its L (a
symbol that went off the plotter and returned, or a freed number given to a new target: the
stream alone cannot tell). Stops 3 s after the stream does.

    python3 tools/plotter_churn.py 29111 &
    target/release/tracker-host --link inproc demo --ais-truth ... --speedup 60 \
        --nmea-out udp:127.0.0.1:29111
    wait

Outside the product (standard library only). At `--speedup max` a receiver's socket buffer
may drop datagrams; 60 loses none here.
"""
import socket
import sys


def main() -> None:
    port = int(sys.argv[1])
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 8 << 20)
    sock.bind(("127.0.0.1", port))
    sock.settimeout(3)
    ended, sent, lost, back = set(), 0, 0, 0
    try:
        while True:
            for line in sock.recv(65536).decode(errors="replace").splitlines():
                if "TTM," not in line:
                    continue
                fields = line.split("*")[0].split(",")
                number, status = fields[1], fields[12]
                if status == "L":
                    lost += 1
                    ended.add(number)
                else:
                    sent += 1
                    if number in ended:
                        ended.discard(number)
                        back += 1
    except socket.timeout:
        pass
    print(f"TTM T/Q {sent}, L {lost}, came back after L {back}")


if __name__ == "__main__":
    main()
