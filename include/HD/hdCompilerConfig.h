/* vmhaptics open HD API: compiler configuration (kept for the clients
 * that include it by name; everything lives in hdExport.h). */
#ifndef VMHAPTICS_HD_COMPILER_CONFIG_H_
#define VMHAPTICS_HD_COMPILER_CONFIG_H_
#include <HD/hdExport.h>
#endif /* VMHAPTICS_HD_COMPILER_CONFIG_H_ */
