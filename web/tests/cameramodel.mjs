// A .cameramodel's text (mrcal's Python-literal dict) read back, and its pose and projection:
// what the calibration tests compare with the synthetic truth.
import fs from 'node:fs';

export function readModel(file) {
  const text = fs.readFileSync(file, 'utf8');
  const list = (key) => {
    const m = new RegExp(`'${key}'\\s*:\\s*\\[([^\\]]*)\\]`).exec(text);
    if (!m) throw new Error(`${file}: no '${key}'`);
    return m[1].split(',').map((v) => v.trim()).filter(Boolean).map(Number);
  };
  return { intrinsics: list('intrinsics'), extrinsics: list('extrinsics'), text };
}

// Rodrigues: the rotation matrix of an axis-angle vector.
export function rodrigues([rx, ry, rz]) {
  const th = Math.hypot(rx, ry, rz);
  if (th < 1e-15) return [[1, 0, 0], [0, 1, 0], [0, 0, 1]];
  const [x, y, z] = [rx / th, ry / th, rz / th];
  const c = Math.cos(th);
  const s = Math.sin(th);
  const C = 1 - c;
  return [
    [c + x * x * C, x * y * C - z * s, x * z * C + y * s],
    [y * x * C + z * s, c + y * y * C, y * z * C - x * s],
    [z * x * C - y * s, z * y * C + x * s, c + z * z * C],
  ];
}

// extrinsics = mrcal's rt_cam_ref (cam_from_ground): centre = -R^T t.
export function pose(model) {
  const R = rodrigues(model.extrinsics.slice(0, 3));
  const t = model.extrinsics.slice(3, 6);
  const centre = [0, 1, 2].map((j) => -(R[0][j] * t[0] + R[1][j] * t[1] + R[2][j] * t[2]));
  return { R, centre };
}

// A ground point (metres) in a model's pixels (LENSMODEL_OPENCV8).
export function project(model, [X, Y, Z]) {
  const { R } = pose(model);
  const t = model.extrinsics.slice(3, 6);
  const q = [0, 1, 2].map((i) => R[i][0] * X + R[i][1] * Y + R[i][2] * Z + t[i]);
  const x = q[0] / q[2];
  const y = q[1] / q[2];
  const [fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, k5, k6] = model.intrinsics;
  const r2 = x * x + y * y;
  const radial = (1 + k1 * r2 + k2 * r2 * r2 + k3 * r2 * r2 * r2) / (1 + k4 * r2 + k5 * r2 * r2 + k6 * r2 * r2 * r2);
  const xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x);
  const yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y;
  return [fx * xd + cx, fy * yd + cy];
}

// The angle in degrees of the rotation R.
export function angleDeg(R) {
  const trace = R[0][0] + R[1][1] + R[2][2];
  return (Math.acos(Math.max(-1, Math.min(1, (trace - 1) / 2))) * 180) / Math.PI;
}

// a (3x3) times b (3x3), and a transposed.
export const mul = (a, b) => a.map((row) => [0, 1, 2].map((j) => row[0] * b[0][j] + row[1] * b[1][j] + row[2] * b[2][j]));
export const transpose = (a) => [0, 1, 2].map((i) => [0, 1, 2].map((j) => a[j][i]));

// Model b's camera seen from model a's: {R, t} of b_from_a (both cam_from_ground).
export function relative(a, b) {
  const Ra = rodrigues(a.extrinsics.slice(0, 3));
  const Rb = rodrigues(b.extrinsics.slice(0, 3));
  const ta = a.extrinsics.slice(3, 6);
  const tb = b.extrinsics.slice(3, 6);
  const R = mul(Rb, transpose(Ra));
  const t = [0, 1, 2].map((i) => tb[i] - (R[i][0] * ta[0] + R[i][1] * ta[1] + R[i][2] * ta[2]));
  return { R, t };
}

// How far model a's pose is from model b's: the camera centres' distance in mm and the angle of
// R_a R_b^T in degrees.
export function poseError(a, b) {
  const pa = pose(a);
  const pb = pose(b);
  return {
    centre_mm: Math.hypot(...[0, 1, 2].map((i) => pa.centre[i] - pb.centre[i])) * 1000,
    rotation_deg: angleDeg(mul(pa.R, transpose(pb.R))),
  };
}
