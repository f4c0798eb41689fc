#pragma once
// The calibration wizard's steps (calib/wizard.h), in a header of their own so that a request
// can name one without the wizard (station/request_bodies.h).
namespace ss::calib {

enum class WizardStep { kIntrinsics, kGround, kEnclosure, kDone };
const char* WizardStepName(WizardStep step);  // "intrinsics", "ground", "enclosure", "done"

}  // namespace ss::calib
