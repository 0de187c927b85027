# CTest fixture phantom_fod: the phantom FOD image the shared tractograms
# were tracked from (../shared/data/make_phantom_fod.py, 100³ × 45, ~180 MB)
# and a 12³ crop of it around the centre, made once into OUT (the build
# tree, never ../shared). Does nothing when they exist, or when the shared
# script is missing (the tests then skip).
#   cmake -DPYTHON=... -DSCRIPT=.../make_phantom_fod.py -DOUT=dir -P make_phantom_fod.cmake
if(EXISTS ${OUT}/phantom-fod.nii AND EXISTS ${OUT}/phantom-fod-crop.nii)
  return()
endif()
if(NOT EXISTS ${SCRIPT})
  message(STATUS "no ${SCRIPT}: the phantom FOD tests will skip")
  return()
endif()
string(RANDOM LENGTH 8 suffix)
set(tmp ${OUT}.tmp-${suffix})
file(MAKE_DIRECTORY ${tmp})
execute_process(COMMAND ${PYTHON} ${SCRIPT} ${tmp} RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "make_phantom_fod.py failed (${rc})")
endif()
execute_process(COMMAND ${PYTHON} -c "
import nibabel as nib, numpy as np, sys
img = nib.load(sys.argv[1])
a = np.asarray(img.dataobj)[44:56, 44:56, 44:56, :]
aff = img.affine.copy()
aff[:3, 3] = img.affine[:3, :3] @ [44, 44, 44] + img.affine[:3, 3]
nib.save(nib.Nifti1Image(a.astype(np.float32), aff), sys.argv[2])
" ${tmp}/phantom-fod.nii ${tmp}/phantom-fod-crop.nii RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "cropping the phantom FOD failed (${rc})")
endif()
file(MAKE_DIRECTORY ${OUT})
file(RENAME ${tmp}/phantom-mask.nii ${OUT}/phantom-mask.nii)
file(RENAME ${tmp}/phantom-fod-crop.nii ${OUT}/phantom-fod-crop.nii)
file(RENAME ${tmp}/phantom-fod.nii ${OUT}/phantom-fod.nii)
file(REMOVE_RECURSE ${tmp})
