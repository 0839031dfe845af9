#!/usr/bin/python3
"""Reference m-sequences for tests/plant/signal_test.cpp, from scipy.signal.max_len_seq.

The seed integer maps to the register as bit i -> state[i].
Run: /usr/bin/python3 tests/plant/gen_prbs.py
"""
import numpy as np
from scipy.signal import max_len_seq

for order, seed in [(4, 15), (7, 127), (7, 5), (10, 1023)]:
    state = [(seed >> i) & 1 for i in range(order)]
    seq, _ = max_len_seq(order, state=np.array(state))
    print(f'{{{order}, {seed}, "{"".join(str(int(b)) for b in seq)}"}},')
