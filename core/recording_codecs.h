#pragma once
// The codecs a session's videos are recorded in (storage.recording_codec,
// `synth`, SessionWriter): one table, read by the config's check, the writer
// and the docs (docs/formats.md "Recording codecs").
#include <string>
#include <vector>

namespace ss {

struct RecordingCodec {
  const char* name;  // as the config names it
  bool lossless;     // frames decode to exactly the bytes the camera gave
  bool
      damage_checked;  // every frame carries checksums: a damaged frame is found, not decoded wrong
  const char* what;    // one line for the docs and messages
};

// ffv1 (the default), ffvhuff, mjpeg, h264.
const std::vector<RecordingCodec>& RecordingCodecs();
// nullptr for a name not in the table.
const RecordingCodec* FindRecordingCodec(const std::string& name);
// "ffv1, ffvhuff, mjpeg or h264"
std::string RecordingCodecNames();

}  // namespace ss
