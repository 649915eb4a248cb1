"""Cut pyuff's MPSTD#Set001_2024_10_08_10_27_07.uff (3.5 MB: four binary 58b
time records of 222400 samples) to its first N samples per record, headers
as written but for the two counts that say how long a record is (the 58b
id line's byte count, record 7's number of points). The result,
MPSTD_excerpt.uff of the data set vendor_uff, is what tests/python/test_vendor_uff.py
reads; tools/data/get_data.py runs this script with N = 2048 and checks the
result's SHA-256.

    python3 make_excerpt.py path/to/MPSTD#Set001_2024_10_08_10_27_07.uff OUT.uff [N]
"""

import re
import sys
from pathlib import Path


def excerpt(data: bytes, keep: int) -> bytes:
    out, pos = [], 0
    head = re.compile(rb"    -1\r?\n    58b(.*)\r?\n")
    while True:
        m = head.search(data, pos)
        if not m:
            break
        idline = m.group(0).split(b"\n")[1]
        nbytes = int(idline[31:43])
        lines_end = m.end()
        for _ in range(11):  # ID lines 1-5, records 6-11
            lines_end = data.index(b"\n", lines_end) + 1
        header = data[m.end():lines_end].split(b"\n")
        rec7 = header[6]
        npts = int(rec7[10:20])
        per = nbytes // npts
        new_id = idline[:31] + b"%12d" % (keep * per) + idline[43:]
        header[6] = rec7[:10] + b"%10d" % keep + rec7[20:]
        out.append(b"    -1\n" + new_id + b"\n" + b"\n".join(header))
        out.append(data[lines_end:lines_end + keep * per])
        out.append(b"    -1\n")
        pos = lines_end + nbytes
    return b"".join(out)


if __name__ == "__main__":
    if not 3 <= len(sys.argv) <= 4:
        sys.exit("usage: make_excerpt.py MPSTD_FILE.uff OUT.uff [N]")
    keep = int(sys.argv[3]) if len(sys.argv) > 3 else 2048
    Path(sys.argv[2]).write_bytes(excerpt(Path(sys.argv[1]).read_bytes(), keep))
