#!/usr/bin/env python3
"""dpc's glTF level loader against an independent oracle, the Khronos glTF-Validator (npm
gltf-validator, pinned by tests/gltf/package-lock.json and installed by tests/gltf/install.sh:
an npm registry that cannot be reached fails this test, it is never skipped).

Over the corpus of tests/gltf/corpus.py and mutations.py (valid levels, levels glTF allows and
dpc refuses by design, broken levels), each level is given to the validator and, through its
scene, to `dpc-demo SCENE --offline out.wav` (a user's run), and:
  1. every level the validator reports an error for is refused by dpc: exit status 1, exactly
     one line "dpc-demo: LEVEL: FIELD: ..." naming the level file, no output file, no file of
     the case's folder changed; except the cases of ACCEPTED, each saying why dpc loads it;
  2. every level the validator calls valid (no error; warnings allowed) loads: exit status 0
     and the render written; except the cases of REFUSED, each saying why dpc refuses it;
  3. each case does what the corpus says of it (loads, or is refused with its expected text),
     so a refusal comes from the rule meant, not from an accident;
  4. ACCEPTED and REFUSED hold no entry the validator and dpc agree on (no stale excuse).

  oracle_test.py DPC_DEMO VALIDATOR_DIR [CASE...]
VALIDATOR_DIR: where install.sh puts the validator (the build folder's gltf-validator).
"""
import hashlib
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import corpus  # noqa: E402

# Levels the validator reports an error for that dpc loads, and why that is right.
ACCEPTED = {
    'node_rotation_not_unit': 'dpc reads a rotation of any finite non-zero length as the '
                              'direction it gives, at every entry point (scene/quaternion.h '
                              'unitQuaternion), as it does for a rotation typed in a scene',
}

# Levels glTF 2.0 allows (the validator reports no error) that dpc refuses, and why.
REFUSED = {
    'design_mode_points': 'points have no surface for sound to reflect off',
    'design_mode_lines': 'lines have no surface for sound to reflect off',
    'design_mode_line_loop': 'lines have no surface for sound to reflect off',
    'design_mode_line_strip': 'lines have no surface for sound to reflect off',
    'design_cubic_spline': 'assimp 5.2 reads CUBICSPLINE tangents as keys; dpc cannot play them '
                           'faithfully (docs/scene-format.md)',
    'design_animated_scale': 'moving objects are rigid: an animated scale would change the mesh',
    'design_animation_of_static_node': 'only objects the scene names move; animating static '
                                       'geometry would be dropped silently otherwise',
    'design_quantized_positions': 'assimp 5.2 copies integer positions into floats byte for '
                                  'byte, so dpc refuses them rather than load garbage',
    'design_short_normalized_rotation': 'assimp 5.2 copies integer rotation keys into floats '
                                        'byte for byte',
    'design_sparse_accessor': 'assimp 5.2 applies sparse indices without bounds checks',
    'design_morph_target': 'morph targets change the geometry; dpc needs it rigid',
    'design_buffer_outside_folder': "a level's files must lie in its folder (docs/hardening.md)",
    'design_buffer_symlink_outside': "a symbolic link leading out of the level's folder is "
                                     "refused like a path that does",
    'design_node_depth_200': 'deeper than kMaxGltfNodeDepth (128): the tree is walked '
                             'recursively, and the limit keeps a host thread\'s stack safe',
    'design_channel_without_node': 'a channel without a node animates an extension\'s object, '
                                   'which dpc does not read',
    'design_primitive_without_position': 'a primitive without positions has no surface; '
                                         'refused rather than dropped',
    'design_accessor_without_buffer_view': 'assimp 5.2 cannot read an accessor without a '
                                           'bufferView (all zeros)',
    'anim_channel_path_colour': 'the validator warns only (future extensions may add paths); '
                                'dpc cannot play a path it does not know',
    'anim_interpolation_bouncy': 'the validator warns only; dpc cannot play an interpolation it '
                                 'does not know (assimp would play it as LINEAR)',
    'indices_count_not_3n': 'the validator warns only; assimp would drop the extra indices, so '
                            'dpc refuses rather than load a different mesh',
    'strip_of_two_indices': 'the validator warns only; a strip of two indices has no triangle',
    'extension_required_draco': 'the validator warns only (it cannot check Draco); assimp 5.2 '
                                'cannot decode it, and the file requires it',
    'json_duplicate_key': 'a repeated key makes the file ambiguous (RapidJSON in assimp keeps '
                          'the first value, other parsers the last), as in a scene JSON',
}

RUN_SECONDS = 120


def validate(validator_dir, files):
    """The validator's verdict per file: (errors, first error)."""
    script = os.path.join(HERE, 'validate.js')
    env = dict(os.environ, NODE_PATH=os.path.join(validator_dir, 'node_modules'))
    p = subprocess.run(['node', script] + files, capture_output=True, text=True, env=env,
                       timeout=600)
    if p.returncode != 0:
        sys.exit('oracle_test: the validator failed:\n' + p.stderr[-2000:])
    out = {}
    for line in p.stdout.splitlines():
        r = json.loads(line)
        out[r['file']] = (r['errors'], r['first'])
    missing = [f for f in files if f not in out]
    if missing:
        sys.exit('oracle_test: no verdict for ' + ', '.join(missing))
    return out


def digest(folder):
    out = {}
    for root, dirs, files in os.walk(folder):
        for name in files:
            path = os.path.join(root, name)
            out[path] = (hashlib.sha256(open(path, 'rb').read()).hexdigest()
                         if os.path.isfile(path) else 'link')
    return out


def run_dpc(demo, folder, level):
    """dpc's verdict on the case in `folder`: None when it loaded, else its one error line; a
    problem with how it refused or loaded is returned as ('problem', text)."""
    before = digest(folder)
    p = subprocess.run([demo, 'scene.json', '--offline', 'out.wav', '--duration', '0.1'],
                       cwd=folder, capture_output=True, text=True, timeout=RUN_SECONDS,
                       stdin=subprocess.DEVNULL)
    errors = [l for l in p.stderr.splitlines() if l.startswith('dpc-demo:')]
    created = sorted(set(digest(folder)) - set(before))
    if p.returncode == 0:
        renders = [c for c in created if re.fullmatch(r'out(-.+)?\.wav', os.path.basename(c))]
        if errors or not renders or renders != created:
            return ('problem', 'exit 0 with an error line, or without its render (out.wav, or '
                               'out-LISTENER.wav per listener) or with other files: %s' % created)
        for c in created:
            os.remove(c)
        return None
    after = digest(folder)
    if p.returncode != 1:
        return ('problem', 'exit status %d (a crash or signal?): %s' % (p.returncode,
                                                                      p.stderr.strip()[-300:]))
    if len(errors) != 1 or not errors[0].startswith('dpc-demo: ' + level + ': '):
        return ('problem', 'not one error line naming %s: %r' % (level, p.stderr.strip()[-300:]))
    if created or after != before:
        return ('problem', 'files created or changed: %s' % created)
    return errors[0]


def judge(name, expected, valid, verdict):
    """The problems of one case (empty when it passes)."""
    if isinstance(verdict, tuple):
        return [verdict[1]]
    problems = []
    loaded = verdict is None
    if expected is None and not loaded:
        problems.append('the corpus expects it to load; dpc refused: ' + verdict)
    if expected is not None and loaded:
        problems.append('the corpus expects a refusal with %r; dpc loaded it' % expected)
    if expected is not None and not loaded and expected not in verdict:
        problems.append('refused, but not with %r: %s' % (expected, verdict))
    if not valid and loaded and name not in ACCEPTED:
        problems.append('the validator reports errors; dpc loaded it')
    if valid and not loaded and name not in REFUSED:
        problems.append('the validator calls it valid; dpc refused it: ' + verdict)
    if name in ACCEPTED and not (not valid and loaded):
        problems.append('stale ACCEPTED entry: validator and dpc agree')
    if name in REFUSED and not (valid and not loaded):
        problems.append('stale REFUSED entry: validator and dpc agree')
    return problems


def main():
    demo, validator_dir = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    wanted = set(sys.argv[3:])
    install = subprocess.run([os.path.join(HERE, 'install.sh'), validator_dir],
                             capture_output=True, text=True)
    if install.returncode != 0:
        sys.exit('oracle_test: installing the glTF-Validator with npm failed (is the npm '
                 'registry reachable?):\n' + install.stderr[-2000:])
    cases = [c for c in corpus.all_cases() if not wanted or c[0] in wanted]
    work = tempfile.mkdtemp(prefix='dpc_gltf_oracle_')
    try:
        corpus.SIGNAL = os.path.join(work, 'click.wav')
        corpus.write_click(corpus.SIGNAL)
        levels = {}
        for name, make, _ in cases:
            folder = os.path.join(work, name)
            os.makedirs(folder)
            levels[name] = make(folder)
        verdicts = validate(validator_dir, [os.path.join(work, n, levels[n]) for n, _, _ in cases])
        failed = counts = 0
        tally = {'valid': 0, 'invalid': 0, 'loaded': 0, 'refused': 0}
        for name, _, expected in cases:
            errors, first = verdicts[os.path.join(work, name, levels[name])]
            verdict = run_dpc(demo, os.path.join(work, name), levels[name])
            problems = judge(name, expected, errors == 0, verdict)
            tally['valid' if errors == 0 else 'invalid'] += 1
            tally['loaded' if verdict is None else 'refused'] += 1
            print('%s %s: validator %s; dpc %s' % (
                'FAIL' if problems else 'ok  ', name,
                'valid' if errors == 0 else '%d errors (%s)' % (errors, first[:90]),
                'loaded' if verdict is None else verdict if isinstance(verdict, str)
                else 'PROBLEM'))
            for problem in problems:
                print('     ' + problem)
            failed += bool(problems)
            counts += 1
        print('oracle_test: %d cases (validator: %d valid, %d invalid; dpc: %d loaded, %d '
              'refused), %d failed' % (counts, tally['valid'], tally['invalid'], tally['loaded'],
                                       tally['refused'], failed))
        return 1 if failed else 0
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == '__main__':
    sys.exit(main())
