// A shipped scene (scenes/NAME) written into another folder for a browser test, with its files
// named by absolute paths and `edit(desc)` applied: e.g. a door or a dry signal that loops, so
// a check sees what it needs whenever on the offline clock it starts.
import fs from 'node:fs';
import path from 'node:path';

export function sceneCopy(source, name, dir, edit) {
  const scenes = path.join(source, 'scenes');
  const desc = JSON.parse(fs.readFileSync(path.join(scenes, name), 'utf8'));
  desc.mesh = path.join(scenes, desc.mesh);
  for (const o of desc.objects || []) o.mesh = path.join(scenes, o.mesh);
  for (const s of desc.sources || []) if (s.signal) s.signal = path.join(scenes, s.signal);
  edit(desc);
  const file = path.join(dir, name.replace(/\.json$/, '-copy.json'));
  fs.writeFileSync(file, JSON.stringify(desc));
  return file;
}
