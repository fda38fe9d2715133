// The attributes of LAS point records (R15 section 2.6) that PointRecord does not hold, to and from the
// compact tail of cloud/point_attributes.h. A tail packed from a record of one format and unpacked into a
// record of the same format gives back its bytes exactly (with toPointRecord's fields and the record
// writer's); into another format the values are converted: the scan angle between degrees (formats 0-5)
// and 0.006 degree units (formats 6-10), rounded to nearest; number of returns above 7 and the
// overlap flag and scanner channel, which formats 0-5 cannot hold, are clamped and dropped. The wave
// packet fields of formats 4, 5, 9 and 10 are not carried.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cloud/point_attributes.h"
#include "io/io_util.h"
#include "io/las/las_format.h"

namespace pointrast::io::detail {

// What records of pointFormat (0-10) followed by extraBytes bytes carry besides PointRecord's fields.
PointAttributes lasAttributes(int pointFormat, uint16_t extraBytes);

// Packs the attributes of one record (of pointFormat, with its extra bytes after the format's size) into
// the tail of `layout`, whose fields must include lasAttributes(pointFormat, ...)'s. Fields of the layout
// the format lacks are zero.
void packLasAttributes(const uint8_t* record, int pointFormat, const AttributeLayout& layout,
                       const PointAttributes& attributes, uint8_t* tail);

// Writes the tail's attributes into a record of pointFormat whose PointRecord fields are already there
// (number of returns and the flags share their bytes with the return number and, in formats 0-5, the
// classification: those bits are kept). Extra bytes go after the format's size when the layout has them.
// The tail's attributes describe its values (the scan angle's unit). A layout without a number of
// returns leaves the record's number of returns bits as they are.
void unpackLasAttributes(const uint8_t* tail, const AttributeLayout& layout,
                         const PointAttributes& attributes, int pointFormat, uint8_t* record);

// One field of the extra bytes, from an extra bytes descriptor (R15 section 2.20, Table 24).
struct ExtraBytesField {
  std::string name, description;
  uint8_t dataType = 0; // 0: undocumented bytes; 1-10 one value; 11-20 two, 21-30 three (deprecated)
  uint8_t options = 0;  // bit 3: scale given, bit 4: offset given; for type 0 the byte count
  uint16_t offset = 0;  // of the field within a record's extra bytes
  uint16_t bytes = 0;
  int elements = 1;
  int elementSize = 1;
  const char* type = "uint8"; // one element's type as Potree 2.0 names it (undocumented bytes: uint8)
  double scale[3] = {1, 1, 1};
  double valueOffset[3] = {0, 0, 0};
};

// The fields of records with extraBytes extra bytes, from their descriptors: the payloads of every extra
// bytes VLR (LASF_Spec, record 4) of the file, concatenated in file order (192 bytes each). Bytes past the
// last described field become one undocumented field named "extra bytes". Throws InputError (prefixed
// with `where`) for a payload that is not whole descriptors, an unknown data type or fields longer than
// the records' extra bytes.
std::vector<ExtraBytesField> parseExtraBytes(const std::vector<uint8_t>& descriptors, uint16_t extraBytes,
                                             const std::string& where);

// The tails of a LAS file's records: lasAttributes() of its format and extra bytes (the record length
// past the format's size), and the payloads of its extra bytes VLRs. Descriptors that parseExtraBytes()
// refuses are left out (the bytes stay, undocumented).
TailFormat lasTailFormat(const InputFile& file, const LasHeader& header);
// Packs `count` records of pointFormat with extraBytes extra bytes (0, or tail's count), stride bytes
// apart, into tails of tail.layout (see packLasAttributes).
void packLasTails(const uint8_t* records, uint64_t stride, uint64_t count, int pointFormat,
                  uint16_t extraBytes, const TailFormat& tail, uint8_t* tails);

} // namespace pointrast::io::detail
