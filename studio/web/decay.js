// Room parameters of one band's energy response, as dpc-analyze computes them
// (analysis/room_parameters.cpp, analyzeEnergyDecay): from the onset t0, the direct sound's
// arrival when it lies in the first non-zero bin (that bin then counts from t0 to its end), else
// that bin's start; the Schroeder backward integral, T30 (-5..-35 dB) and EDT (0..-10 dB) by
// least squares on t0 and the later bins' starts, each range ending at least 10 dB above the
// curve's level at 90 % of the record; C80 and D50 with the bin straddling t0 + 80 / 50 ms split
// in proportion to time.

const kFloorHeadroomDb = 10, kFloorFraction = 0.9, kMinRegressionPoints = 3;

/// Bin k's start (s after t0) when bin 0 is `first` s wide and the rest dt.
function binStart(k, first, dt) {
  return k === 0 ? 0 : first + (k - 1) * dt;
}

/// Decay time from the least-squares slope of levelDb over [loDb, hiDb], or NaN.
function decayTime(levelDb, first, dt, hiDb, loDb, floorDb) {
  if (loDb < floorDb + kFloorHeadroomDb) return NaN;
  if (!levelDb.length || !(levelDb[levelDb.length - 1] <= loDb)) return NaN;
  let sx = 0, sy = 0, sxx = 0, sxy = 0, n = 0;
  for (let k = 0; k < levelDb.length; ++k) {
    const l = levelDb[k];
    if (l > hiDb) continue;
    if (l < loDb) break;
    const x = binStart(k, first, dt);
    sx += x; sy += l; sxx += x * x; sxy += x * l; ++n;
  }
  if (n < kMinRegressionPoints) return NaN;
  const denom = n * sxx - sx * sx;
  if (!(denom > 0)) return NaN;
  const slope = (n * sxy - sx * sy) / denom;
  return slope < 0 ? -60 / slope : NaN;
}

/// Energy in [t0, t0 + window) of e (from the onset): whole bins plus the straddling bin's share.
function earlyEnergy(e, first, dt, window) {
  let sum = 0;
  for (let k = 0; k < e.length; ++k) {
    const share = (window - binStart(k, first, dt)) / (k === 0 ? first : dt);
    if (share >= 1 - 1e-9) { sum += e[k]; continue; }
    if (share > 1e-9) sum += share * e[k];
    break;
  }
  return sum;
}

/// {onsetSeconds, curveDb (Schroeder curve from the onset), t30, edt, c80, d50}; NaN when the
/// band holds no energy or a range is not reached. t0: the direct sound's arrival (s), or null.
export function roomParameters(energy, dt, t0 = null) {
  const none = { onsetSeconds: NaN, curveDb: [], t30: NaN, edt: NaN, c80: NaN, d50: NaN };
  let onset = 0;
  while (onset < energy.length && !(energy[onset] > 0)) ++onset;
  if (onset === energy.length) return none;
  const inside = t0 !== null && t0 >= onset * dt && t0 < (onset + 1) * dt;
  const first = inside ? (onset + 1) * dt - t0 : dt;
  const e = energy.slice(onset).map((v) => (v > 0 ? v : 0));
  const tail = new Array(e.length);
  for (let k = e.length - 1, acc = 0; k >= 0; --k) tail[k] = acc += e[k];
  const total = tail[0];
  if (!(total > 0) || !isFinite(total)) return none;
  const curveDb = tail.map((t) => (t > 0 ? 10 * Math.log10(t / total) : -Infinity));
  for (let k = 1; k < curveDb.length; ++k) curveDb[k] = Math.min(curveDb[k], curveDb[k - 1]);
  const floorDb = curveDb[Math.min(e.length - 1, Math.floor(kFloorFraction * e.length))];
  const early80 = earlyEnergy(e, first, dt, 0.08), late80 = Math.max(0, total - early80);
  return {
    onsetSeconds: inside ? t0 : onset * dt,
    curveDb,
    t30: decayTime(curveDb, first, dt, -5, -35, floorDb),
    edt: decayTime(curveDb, first, dt, 0, -10, floorDb),
    c80: late80 <= 0 ? Infinity : early80 <= 0 ? -Infinity : 10 * Math.log10(early80 / late80),
    d50: Math.min(1, Math.max(0, earlyEnergy(e, first, dt, 0.05) / total)),
  };
}
