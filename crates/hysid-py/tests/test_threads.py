"""The GIL is released during fits: two threads fit at once (figures printed, not
asserted: timing depends on the machine)."""
import threading
import time

import hysid


def test_two_threads(example1):
    x, y = example1
    fit = lambda: hysid.identify_cascade(x, y, na=2, nb=2, delay=1)  # noqa: E731
    fit()  # warm up
    t0 = time.perf_counter()
    seq = [fit(), fit()]
    t_seq = time.perf_counter() - t0
    out = [None, None]

    def work(i):
        out[i] = fit()

    threads = [threading.Thread(target=work, args=(i,)) for i in range(2)]
    t0 = time.perf_counter()
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    t_par = time.perf_counter() - t0
    print(f"\ntwo cascade fits: one after the other {t_seq:.3f} s, two threads {t_par:.3f} s, "
          f"speed-up {t_seq / t_par:.2f}x")
    assert [r.parameters for r in out] == [r.parameters for r in seq]
