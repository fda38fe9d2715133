#include "io/las/las_tail_values.h"

#include <cstring>
#include <string_view>

namespace pointrast::io::detail {

namespace {

constexpr double kAngleUnit = 0.006; // degrees per unit of the scan angle of LAS formats 6-10

template <class T> T at(const uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

// One element of an extra bytes field, by its type's Potree 2.0 name (ExtraBytesField::type).
lod::TailValue::Number element(std::string_view type, const uint8_t* p) {
  if (type == "int8") return int64_t(at<int8_t>(p));
  if (type == "uint16") return uint64_t(at<uint16_t>(p));
  if (type == "int16") return int64_t(at<int16_t>(p));
  if (type == "uint32") return uint64_t(at<uint32_t>(p));
  if (type == "int32") return int64_t(at<int32_t>(p));
  if (type == "uint64") return at<uint64_t>(p);
  if (type == "int64") return at<int64_t>(p);
  if (type == "float") return double(at<float>(p));
  if (type == "double") return at<double>(p);
  return uint64_t(*p);
}

double asDouble(const lod::TailValue::Number& n) {
  return std::visit([](auto v) { return double(v); }, n);
}

} // namespace

TailValues::TailValues(const TailFormat& tail) : tail_(tail) {
  if (tail.layout.extraBytes < 0) return;
  try {
    extra_ = parseExtraBytes(tail.extraBytesDescriptors, tail.attributes.extraBytes, "");
  } catch (const InputError&) {
    extra_ = parseExtraBytes({}, tail.attributes.extraBytes, "");
  }
}

std::vector<lod::TailValue> TailValues::operator()(const uint8_t* tail) const {
  const AttributeLayout& l = tail_.layout;
  std::vector<lod::TailValue> out;
  auto add = [&](const char* name, lod::TailValue::Number value) { out.push_back({name, false, {value}}); };
  if (l.gpsTime >= 0) add("gps_time", at<double>(tail + l.gpsTime));
  if (l.numberOfReturns >= 0) add("number_of_returns", uint64_t(tail[l.numberOfReturns]));
  if (l.scanAngle >= 0) {
    // Formats 0-5 keep whole degrees in an int8 (PotreeConverter's octrees, its low byte alone).
    if (tail_.attributes.extendedScanAngle)
      add("scan_angle", at<int16_t>(tail + l.scanAngle) * kAngleUnit);
    else
      add("scan_angle", int64_t(int8_t(tail[l.scanAngle])));
  }
  if (l.userData >= 0) add("user_data", uint64_t(tail[l.userData]));
  if (l.nir >= 0) add("nir", uint64_t(at<uint16_t>(tail + l.nir)));
  if (l.flags >= 0) {
    // The flags byte of formats 6-10 (point_attributes.h); formats 0-5 have no scanner channel.
    const uint8_t f = tail[l.flags];
    add("classification_flags", uint64_t(f & 0x0F));
    if (tail_.lasPointFormat < 0 || tail_.lasPointFormat >= 6) add("scanner_channel", uint64_t((f >> 4) & 3));
    add("scan_direction_flag", uint64_t((f >> 6) & 1));
    add("edge_of_flight_line", uint64_t(f >> 7));
  }
  if (l.extraBytes >= 0)
    for (const ExtraBytesField& field : extra_) {
      lod::TailValue v{field.name, true, {}};
      const bool scaled = field.dataType != 0 && (field.options & 0x18) != 0;
      for (int e = 0; e < field.elements; ++e) {
        const lod::TailValue::Number n =
            element(field.type, tail + l.extraBytes + field.offset + e * field.elementSize);
        if (scaled && e < 3)
          v.values.push_back(asDouble(n) * field.scale[e] + field.valueOffset[e]);
        else
          v.values.push_back(n);
      }
      out.push_back(std::move(v));
    }
  return out;
}

} // namespace pointrast::io::detail
