#!/usr/bin/python3
# mrcal's own uncertainty for a model written by mrcal-calibrate-cameras (its
# optimization_inputs): the per-parameter standard deviation of the intrinsics
# and the projection uncertainty (worst direction) at given pixels and distance.
# Used by tests/e2e/calibrate_mrcal_e2e_test.cc. Run with the Debian python,
# which has the mrcal module:
#   /usr/bin/python3 mrcal_uncertainty.py MODEL DISTANCE_M "u,v u,v ..."
# Prints one JSON object.
import json
import sys

import numpy as np
import mrcal
import mrcal.model_analysis as ma


def main():
    path, distance, pixels = sys.argv[1], float(sys.argv[2]), sys.argv[3]
    model = mrcal.cameramodel(path)
    oi = model.optimization_inputs()
    icam = model.icam_intrinsics()
    lensmodel, intrinsics = model.intrinsics()

    # Var(b) = sigma^2 inv(JtJ) Jobs^t Jobs inv(JtJ), the way mrcal propagates
    # calibration noise (http://mrcal.secretsauce.net/uncertainty.html), on its
    # packed state b* = inv(D) b.
    _, x, jpacked, factorization = mrcal.optimizer_callback(**oi)
    nstate = jpacked.shape[1]
    d = np.ones(nstate, dtype=float)
    mrcal.unpack_state(d, **oi)  # in place: d = diag(D)
    i0 = mrcal.state_index_intrinsics(icam, **oi)
    nparams = len(intrinsics)
    df_dbpacked = np.zeros((nparams, nstate))
    for i in range(nparams):
        df_dbpacked[i, i0 + i] = d[i0 + i]
    nobs = mrcal.num_measurements_boards(**oi)
    if nobs == mrcal.num_measurements(**oi):
        nobs = None
    sigma = float(np.std(mrcal.residuals_chessboard(oi, residuals=x).ravel()))
    var = ma._propagate_calibration_uncertainty(df_dbpacked, factorization, jpacked, nobs, sigma, 'covariance')

    points = []
    for token in pixels.split():
        u, v = (float(t) for t in token.split(','))
        q = np.array((u, v), dtype=float)
        p_cam = mrcal.unproject(q, lensmodel, intrinsics, normalize=True) * distance
        stdev = mrcal.projection_uncertainty(p_cam, model, what='worstdirection-stdev')
        points.append({'pixel': [u, v], 'stdev_px': float(stdev)})

    print(json.dumps({
        'lensmodel': lensmodel,
        'intrinsics': [float(t) for t in intrinsics],
        'intrinsics_stdev': [float(np.sqrt(max(var[i, i], 0.0))) for i in range(nparams)],
        'observed_pixel_uncertainty': sigma,
        'distance_m': distance,
        'projection': points,
    }))


if __name__ == '__main__':
    main()
