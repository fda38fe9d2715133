// Reads a COPC file with copc.js (the npm package "copc", decoding through laz-perf: an implementation
// independent of pointrast's) and prints one line per node with points, in key order:
//   D-X-Y-Z COUNT SHA256
// where SHA256 hashes the node's points as sorted text lines "x y z intensity return class source r g b"
// (integers as stored) joined by "\n". The first line is "COPC POINTS NODES PAGES" from the header and the
// hierarchy. The COPC writer's tests compute the same lines from the points they built.
//
//   node tests/web/copc_nodes.mjs FILE.copc.laz
//
// With --records it prints, instead, what a lossless archive must hold: "RECORDS COUNT LENGTH SHA256",
// SHA256 over the lowercase hex of every whole point record of every node (every attribute and the extra
// bytes, as stored), sorted and joined by "\n"; "EB NAME..." the extra bytes dimensions copc.js parsed from
// the file's VLR; and "SUM NAME VALUE" for GpsTime and each of them, summed over every point through
// copc.js's own dimension getters (its reading of the extra bytes descriptors).
//
//   node tests/web/copc_nodes.mjs --records FILE.copc.laz
import { createHash } from 'node:crypto';
import copcPackage from 'copc';

const { Copc, Hierarchy } = copcPackage;
const records = process.argv[2] === '--records';
const file = process.argv[records ? 3 : 2];
if (!file) {
  console.error('usage: node copc_nodes.mjs [--records] FILE.copc.laz');
  process.exit(2);
}
const copc = await Copc.create(file);
const { pointDataRecordFormat: format, pointDataRecordLength: length } = copc.header;

// Every page, from the root page down.
const nodes = {};
let pageCount = 0;
const pending = [copc.info.rootHierarchyPage];
while (pending.length) {
  const page = pending.pop();
  ++pageCount;
  const subtree = await Hierarchy.load(file, page);
  Object.assign(nodes, subtree.nodes);
  pending.push(...Object.values(subtree.pages));
}

if (records) {
  const hex = [];
  const names = copc.eb.map((e) => e.name);
  const sums = Object.fromEntries(['GpsTime', ...names].map((n) => [n, 0]));
  for (const node of Object.values(nodes)) {
    if (node.pointCount === 0) continue;
    const buffer = await Copc.loadPointDataBuffer(file, copc.header, node);
    for (let at = 0; at < buffer.byteLength; at += length)
      hex.push(Buffer.from(buffer.buffer, buffer.byteOffset + at, length).toString('hex'));
    const view = await Copc.loadPointDataView(file, copc, node);
    for (const name of Object.keys(sums)) {
      const get = view.getter(name);
      for (let i = 0; i < view.pointCount; ++i) sums[name] += get(i);
    }
  }
  hex.sort();
  console.log(`RECORDS ${hex.length} ${length} ${createHash('sha256').update(hex.join('\n')).digest('hex')}`);
  console.log(['EB', ...names].join(' '));
  for (const [name, sum] of Object.entries(sums)) console.log(`SUM ${name} ${sum.toPrecision(15)}`);
  process.exit(0);
}

const keyOrder = (a, b) => {
  const ka = a.split('-').map(Number), kb = b.split('-').map(Number);
  for (let i = 0; i < 4; ++i) if (ka[i] !== kb[i]) return ka[i] - kb[i];
  return 0;
};
const lines = [];
let total = 0;
for (const key of Object.keys(nodes).sort(keyOrder)) {
  const node = nodes[key];
  if (node.pointCount === 0) continue;
  const buffer = await Copc.loadPointDataBuffer(file, copc.header, node);
  if (buffer.byteLength !== node.pointCount * length) {
    console.error(`${key}: ${buffer.byteLength} bytes decoded for ${node.pointCount} points`);
    process.exit(1);
  }
  const dv = new DataView(buffer.buffer, buffer.byteOffset, buffer.byteLength);
  const points = [];
  for (let i = 0, at = 0; i < node.pointCount; ++i, at += length) {
    // Point formats 6-8 (LAS 1.4 R15, Tables 7-9): return number in the low 4 bits of byte 14,
    // classification at 16, point source id at 20, RGB at 30 (formats 7 and 8).
    const rgb = format >= 7 ? [dv.getUint16(at + 30, true), dv.getUint16(at + 32, true), dv.getUint16(at + 34, true)]
                            : [0, 0, 0];
    points.push([dv.getInt32(at, true), dv.getInt32(at + 4, true), dv.getInt32(at + 8, true),
                 dv.getUint16(at + 12, true), dv.getUint8(at + 14) & 0x0f, dv.getUint8(at + 16),
                 dv.getUint16(at + 20, true), ...rgb].join(' '));
  }
  points.sort();
  lines.push(`${key} ${node.pointCount} ${createHash('sha256').update(points.join('\n')).digest('hex')}`);
  total += node.pointCount;
}
console.log(`COPC ${copc.header.pointCount} ${lines.length} ${pageCount}`);
if (total !== copc.header.pointCount) {
  console.error(`the nodes hold ${total} points, the header says ${copc.header.pointCount}`);
  process.exit(1);
}
for (const line of lines) console.log(line);
