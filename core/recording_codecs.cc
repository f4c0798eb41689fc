#include "core/recording_codecs.h"

namespace ss {

const std::vector<RecordingCodec>& RecordingCodecs() {
  static const std::vector<RecordingCodec> codecs = {
      {"ffv1", true, true,
       "lossless, FFV1 level 3 (16 slices at 720p and up, a CRC per slice); the default"},
      {"ffvhuff", true, false,
       "lossless (Huffyuv, colour as planes), several times faster to decode than ffv1 for more "
       "bytes; "
       "no checksums: a damaged frame is found only when it does not decode"},
      {"mjpeg", false, false,
       "JPEG per frame (lossy); an MJPEG camera's JPEGs are stored as they came"},
      {"h264", false, false, "libx264, zero latency, no B-frames (lossy)"},
  };
  return codecs;
}

const RecordingCodec* FindRecordingCodec(const std::string& name) {
  for (const RecordingCodec& c : RecordingCodecs()) {
    if (name == c.name) return &c;
  }
  return nullptr;
}

std::string RecordingCodecNames() {
  std::string out;
  const auto& codecs = RecordingCodecs();
  for (size_t i = 0; i < codecs.size(); ++i) {
    out += codecs[i].name;
    if (i + 2 < codecs.size())
      out += ", ";
    else if (i + 2 == codecs.size())
      out += " or ";
  }
  return out;
}

}  // namespace ss
