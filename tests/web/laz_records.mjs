// Decodes a LAZ file with laz-perf (LASzip's format compiled to WebAssembly, an implementation
// independent of pointrast's) and prints "POINTS SHA256" of its point records, as an uncompressed LAS
// file would hold them. The LAZ writer's tests compare it with the records pointrast wrote.
//
//   node tests/web/laz_records.mjs FILE.laz
import { readFileSync } from 'node:fs';
import { createHash } from 'node:crypto';
import { createLazPerf } from 'laz-perf';

const file = process.argv[2];
if (!file) {
  console.error('usage: node laz_records.mjs FILE.laz');
  process.exit(2);
}
const bytes = readFileSync(file);
const lp = await createLazPerf();
const filePtr = lp._malloc(bytes.length);
lp.HEAPU8.set(bytes, filePtr);
const laszip = new lp.LASZip();
laszip.open(filePtr, bytes.length);
const count = laszip.getCount();
const length = laszip.getPointLength();
const pointPtr = lp._malloc(length);
const hash = createHash('sha256');
for (let i = 0; i < count; ++i) {
  laszip.getPoint(pointPtr);
  hash.update(lp.HEAPU8.subarray(pointPtr, pointPtr + length));
}
laszip.delete();
lp._free(pointPtr);
lp._free(filePtr);
console.log(`${count} ${hash.digest('hex')}`);
