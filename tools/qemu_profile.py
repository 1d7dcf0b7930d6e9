#!/usr/bin/env python3
"""Where a firmware ELF's instructions go under QEMU: a profile from QEMU's block trace.

Runs the ELF on mps2-an386 with `-d in_asm,exec,nochain` (every translated block's
instructions, and every block executed), counts the instructions each address executed,
and adds them up by source line and by function, inlined frames resolved by
`arm-none-eabi-addr2line -i` (Debian: binutils-arm-none-eabi). A tool for the firmware
engineer, outside the product: the bench's figures come from `tracker-host bench-mcu`.

    tools/qemu_profile.py target/thumbv7em-none-eabihf/release/bench \\
        --from scan_row:1 --to scan_row:2 --top 40

`--from SYM:N` / `--to SYM:M` count only from the N-th entry into the function whose
demangled path is SYM or ends with `::SYM` to the M-th entry into the other, entries counted from the
start of the run (default: the whole run). `--regions` counts only inside the bench's measured regions (between entries
into `icount::region_begin` and `icount::region_end`), so a row's figure and its profile
agree; the rest of the bench (the simulator, the host's part) is left out. The trace of a whole bench run is a few GB: it is streamed from QEMU, not kept.
"""

import argparse
import collections
import re
import subprocess
import sys

IN_LINE = re.compile(r"^0x([0-9a-f]+):\s")
TRACE = re.compile(r"^Trace \d+: 0x[0-9a-f]+ \[[0-9a-f]+/([0-9a-f]+)/")


def symbols(elf):
    out = subprocess.run(["arm-none-eabi-nm", "-C", elf], capture_output=True, text=True,
                         check=True).stdout
    table = []
    for line in out.splitlines():
        parts = line.split(" ", 2)
        if len(parts) == 3 and parts[1] in "tTW":
            table.append((int(parts[0], 16) & ~1, parts[2]))
    return table


def named(name, needle):
    """The demangled `name` is `needle`, or ends with `::needle` (a path's tail)."""
    return name == needle or name.endswith("::" + needle)


def entry_points(table, needle):
    return {a for a, name in table if named(name, needle)}


def parse_marker(text):
    if not text:
        return None
    name, _, n = text.rpartition(":") if text.rsplit(":", 1)[-1].isdigit() else (text, "", "")
    return name, int(n or 1)


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("elf")
    ap.add_argument("--from", dest="start", help="SYM[:N] start counting at its N-th entry")
    ap.add_argument("--to", dest="stop", help="SYM[:N] stop counting at its N-th entry")
    ap.add_argument("--regions", action="store_true",
                    help="count only inside icount::region_begin .. region_end")
    ap.add_argument("--callers", metavar="SYM",
                    help="also split a leaf function's instructions by the line that called it")
    ap.add_argument("--top", type=int, default=30)
    ap.add_argument("--timeout", type=int, default=900)
    args = ap.parse_args()

    table = symbols(args.elf)
    start, stop = parse_marker(args.start), parse_marker(args.stop)
    start_at = entry_points(table, start[0]) if start else set()
    stop_at = entry_points(table, stop[0]) if stop else set()
    leaf = None
    if args.callers:
        named = sorted(table)
        for k, (a, name) in enumerate(named):
            if named(name, args.callers):
                end = named[k + 1][0] if k + 1 < len(named) else a + 4096
                leaf = (a, end)
                break
        if leaf is None:
            sys.exit("qemu_profile: the --callers symbol is not in the ELF")
    begin_at = entry_points(table, "icount::region_begin") if args.regions else set()
    end_at = entry_points(table, "icount::region_end") if args.regions else set()
    if args.regions and not (begin_at and end_at):
        sys.exit("qemu_profile: the ELF has no icount::region_begin/region_end")
    if start and not start_at or stop and not stop_at:
        sys.exit("qemu_profile: a --from/--to symbol is not in the ELF")

    qemu = ["timeout", str(args.timeout), "qemu-system-arm", "-machine", "mps2-an386",
            "-cpu", "cortex-m4", "-nographic", "-monitor", "none", "-serial", "null",
            "-icount", "shift=0", "-semihosting-config", "enable=on,target=native",
            "-kernel", args.elf, "-d", "in_asm,exec,nochain", "-D", "/dev/stdout"]
    proc = subprocess.Popen(qemu, stdout=subprocess.PIPE, text=True, errors="replace",
                            bufsize=1 << 20)
    blocks = {}  # block start -> its instructions' addresses
    current = None
    executed = collections.Counter()  # block start -> executions counted
    called_from = collections.Counter()  # (caller block, callee block) -> executions
    last_pc, caller = None, None
    counting = start is None
    inside = not args.regions
    seen_start = seen_stop = 0
    for line in proc.stdout:
        m = TRACE.match(line)
        if m:
            current = None
            pc = int(m.group(1), 16)
            # Entries are counted from the start of the run, whether counting or not.
            if pc in start_at:
                seen_start += 1
                counting = counting or seen_start == start[1]
            if pc in stop_at:
                seen_stop += 1
                if seen_stop == stop[1]:
                    break
            if pc in begin_at:
                inside = True
            elif pc in end_at:
                inside = False
            if counting and inside:
                executed[pc] += 1
                if leaf:
                    in_leaf = leaf[0] <= pc < leaf[1]
                    if in_leaf and caller is None:
                        caller = last_pc
                    elif not in_leaf:
                        caller = None
                    if in_leaf:
                        called_from[(caller, pc)] += 1
            last_pc = pc
            continue
        if line.startswith("IN:"):
            current = None
            continue
        m = IN_LINE.match(line)
        if m:
            addr = int(m.group(1), 16)
            if current is None:
                current = addr
                blocks[addr] = []
            blocks[current].append(addr)
    proc.kill()
    proc.wait()

    per_addr = collections.Counter()
    for pc, n in executed.items():
        for a in blocks.get(pc, []):
            per_addr[a] += n
    total = sum(per_addr.values())
    if not total:
        sys.exit("qemu_profile: nothing counted")

    addrs = sorted(per_addr)
    out = subprocess.run(["arm-none-eabi-addr2line", "-e", args.elf, "-f", "-C", "-i", "-a"],
                         input="\n".join(hex(a) for a in addrs), capture_output=True,
                         text=True, check=True).stdout.splitlines()
    # Output per address: its 0x line, then (function, file:line) pairs, innermost first.
    frames = {}
    i = 0
    cur = None
    while i < len(out):
        if out[i].startswith("0x"):
            cur = int(out[i], 16)
            frames[cur] = []
            i += 1
            continue
        fn, loc = out[i], out[i + 1] if i + 1 < len(out) else "?"
        frames[cur].append((fn, loc.split(" ")[0]))
        i += 2

    if leaf:
        by_caller = collections.Counter()
        for (c, pc), n in called_from.items():
            cost = n * len(blocks.get(pc, []))
            last = blocks.get(c, [c])[-1] if c is not None else None
            f = frames.get(last) if last is not None else None
            if f is None and last is not None:
                extra = subprocess.run(["arm-none-eabi-addr2line", "-e", args.elf, "-f", "-C",
                                        "-i", hex(last)], capture_output=True, text=True).stdout
                lines = extra.splitlines()
                f = [(lines[i], lines[i + 1].split(" ")[0]) for i in range(0, len(lines) - 1, 2)]
                frames[last] = f
            where = " <- ".join(re.sub(r"^.*/(src|library)/", r"\1/", loc) for _, loc in (f or [])[:3])
            by_caller[where or "?"] += cost

    by_line = collections.Counter()
    by_fn = collections.Counter()
    by_outer = collections.Counter()
    for a, n in per_addr.items():
        f = frames.get(a) or [("?", "?")]
        fn, loc = f[0]
        short = re.sub(r"^.*/(src|library)/", r"\1/", loc)
        by_line[f"{short}  ({fn[:60]})"] += n
        by_fn[fn[:100]] += n
        by_outer[f[-1][0][:100]] += n

    print(f"instructions counted: {total:,}")
    if leaf:
        print(f"\n{args.callers}, by the line that called it (innermost first):")
        for k, n in by_caller.most_common(args.top):
            print(f"{n:>12,} {100.0 * n / total:5.1f}%  {k}")
    for title, counter in (("by function (innermost frame)", by_fn),
                           ("by function (outermost frame)", by_outer),
                           ("by source line (innermost frame)", by_line)):
        print(f"\n{title}:")
        for k, n in counter.most_common(args.top):
            print(f"{n:>12,} {100.0 * n / total:5.1f}%  {k}")


if __name__ == "__main__":
    main()
