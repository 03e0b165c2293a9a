// Room parameters of one band's energy response, as dpc-analyze computes them
// (analysis/room_parameters.cpp, analyzeEnergyDecay): the Schroeder backward integral from the
// first non-zero bin, T30 (-5..-35 dB) and EDT (0..-10 dB) by least squares on bin starts, each
// range ending at least 10 dB above the curve's level at 90 % of the record; C80 and D50 with
// the bin straddling 80 / 50 ms split in proportion to time.

const kFloorHeadroomDb = 10, kFloorFraction = 0.9, kMinRegressionPoints = 3;

/// Decay time from the least-squares slope of levelDb over [loDb, hiDb], or NaN.
function decayTime(levelDb, dt, hiDb, loDb, floorDb) {
  if (loDb < floorDb + kFloorHeadroomDb) return NaN;
  if (!levelDb.length || !(levelDb[levelDb.length - 1] <= loDb)) return NaN;
  let sx = 0, sy = 0, sxx = 0, sxy = 0, n = 0;
  for (let k = 0; k < levelDb.length; ++k) {
    const l = levelDb[k];
    if (l > hiDb) continue;
    if (l < loDb) break;
    const x = k * dt;
    sx += x; sy += l; sxx += x * x; sxy += x * l; ++n;
  }
  if (n < kMinRegressionPoints) return NaN;
  const denom = n * sxx - sx * sx;
  if (!(denom > 0)) return NaN;
  const slope = (n * sxy - sx * sy) / denom;
  return slope < 0 ? -60 / slope : NaN;
}

/// Energy in [0, window) of e (from the onset): whole bins plus the straddling bin's share.
function earlyEnergy(e, dt, window) {
  let q = window / dt;
  if (Math.abs(q - Math.round(q)) < 1e-9) q = Math.round(q);
  const whole = Math.floor(q);
  let sum = 0;
  for (let k = 0; k < Math.min(whole, e.length); ++k) sum += e[k];
  if (whole < e.length) sum += (q - whole) * e[whole];
  return sum;
}

/// {onsetSeconds, curveDb (Schroeder curve from the onset), t30, edt, c80, d50}; NaN when the
/// band holds no energy or a range is not reached.
export function roomParameters(energy, dt) {
  const none = { onsetSeconds: NaN, curveDb: [], t30: NaN, edt: NaN, c80: NaN, d50: NaN };
  let onset = 0;
  while (onset < energy.length && !(energy[onset] > 0)) ++onset;
  if (onset === energy.length) return none;
  const e = energy.slice(onset).map((v) => (v > 0 ? v : 0));
  const tail = new Array(e.length);
  for (let k = e.length - 1, acc = 0; k >= 0; --k) tail[k] = acc += e[k];
  const total = tail[0];
  if (!(total > 0) || !isFinite(total)) return none;
  const curveDb = tail.map((t) => (t > 0 ? 10 * Math.log10(t / total) : -Infinity));
  for (let k = 1; k < curveDb.length; ++k) curveDb[k] = Math.min(curveDb[k], curveDb[k - 1]);
  const floorDb = curveDb[Math.min(e.length - 1, Math.floor(kFloorFraction * e.length))];
  const early80 = earlyEnergy(e, dt, 0.08), late80 = Math.max(0, total - early80);
  return {
    onsetSeconds: onset * dt,
    curveDb,
    t30: decayTime(curveDb, dt, -5, -35, floorDb),
    edt: decayTime(curveDb, dt, 0, -10, floorDb),
    c80: late80 <= 0 ? Infinity : early80 <= 0 ? -Infinity : 10 * Math.log10(early80 / late80),
    d50: Math.min(1, Math.max(0, earlyEnergy(e, dt, 0.05) / total)),
  };
}
