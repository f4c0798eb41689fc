#!/usr/bin/env python3
"""Issue 39's goal, "a spec with any single number at any value: refused or finished within 2 s
and within 1 GiB", as a set of inputs: from a spec that loads (the fuzz corpus' walker scene),
one spec per (number in it, extreme value), and one per optimizer, repeats and clones key the
spec leaves out at each extreme value. spec_fuzz runs them one by one under its limits:

  python3 bench/spec_probe/make_specs.py tests/fuzz/corpus/spec/walker-scene.yaml OUT
  build-fuzz/tests/fuzz/spec_fuzz -timeout=2 -rss_limit_mb=1024 -malloc_limit_mb=1024 OUT/*.yaml

(each input is parsed and its problem built over the walker bank, as `animate` and the studio's
jobs do; bench/RESULTS.md, "Every number of a spec at any value")."""
import os
import re
import sys

EXTREMES = ['0', '-1', '1', '1e300', '-1e300', '1e-300', '1e15', '10000000', '2147483648',
            '-2147483649', '9223372036854775808', '.nan', '.inf', '-.inf', '0.5', '65536']
# Keys the base spec does not set, by the block that takes them (docs/animation.md).
EXTRA_KEYS = {
    'optimizer': ['beam_width', 'changes_per_turn', 'collision_pick_fraction',
                  'goal_pick_fraction', 'threads', 'seed', 'snapshot_every_s', 'fast_frames',
                  'initial_frames', 'goal_fraction', 'd_min'],
    'repeats': ['window_steps'],
    'clones': ['lag_steps'],
}
NUMBER = re.compile(r'(?<![\w.])-?\d+(?:\.\d+)?(?:e[+-]?\d+)?(?![\w.])')


def main():
    if len(sys.argv) != 3:
        sys.exit('usage: make_specs.py BASE_SPEC OUT_DIR')
    base = open(sys.argv[1]).read()
    out = sys.argv[2]
    os.makedirs(out, exist_ok=True)
    specs = []
    for m in NUMBER.finditer(base):
        specs += [base[:m.start()] + v + base[m.end():] for v in EXTREMES]
    for block, keys in EXTRA_KEYS.items():
        for key in keys:
            specs += [base.replace(f'{block}: {{', f'{block}: {{{key}: {v}, ', 1) for v in EXTREMES]
    for i, text in enumerate(specs):
        with open(os.path.join(out, f'p{i:05d}.yaml'), 'w') as f:
            f.write(text)
    print(f'{len(specs)} specs in {out}')


if __name__ == '__main__':
    main()
