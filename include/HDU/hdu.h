/* vmhaptics open HD API utilities, all of them. */
#ifndef VMHAPTICS_HDU_H_
#define VMHAPTICS_HDU_H_
#include <HDU/hduError.h>
#include <HDU/hduMatrix.h>
#include <HDU/hduVector.h>
#endif /* VMHAPTICS_HDU_H_ */
