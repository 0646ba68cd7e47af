/* vmhaptics open HD API: the servo scheduler. Callbacks run on the
 * library's servo thread once per tick, highest priority first. */
#ifndef VMHAPTICS_HD_SCHEDULER_H_
#define VMHAPTICS_HD_SCHEDULER_H_

#include <HD/hdDefines.h>

HD_EXTERN_C_BEGIN

typedef unsigned int HDCallbackCode;
#define HD_CALLBACK_DONE 0     /* unschedule me */
#define HD_CALLBACK_CONTINUE 1 /* call me again next tick */

typedef unsigned long HDSchedulerHandle;
typedef HDCallbackCode(HDCALLBACK* HDSchedulerCallback)(void* pUserData);

typedef unsigned int HDWaitCode;
#define HD_WAIT_CHECK_STATUS 0 /* is it still scheduled? */
#define HD_WAIT_INFINITE 1     /* wait until it is done */

HDAPI void HDAPIENTRY hdStartScheduler(void);
HDAPI void HDAPIENTRY hdStopScheduler(void);
HDAPI void HDAPIENTRY hdSetSchedulerRate(HDulong nRate_Hz);

HDAPI void HDAPIENTRY hdScheduleSynchronous(HDSchedulerCallback pCallback,
                                            void* pUserData,
                                            HDushort nPriority);
HDAPI HDSchedulerHandle HDAPIENTRY hdScheduleAsynchronous(
    HDSchedulerCallback pCallback, void* pUserData, HDushort nPriority);
HDAPI void HDAPIENTRY hdUnschedule(HDSchedulerHandle hHandle);
HDAPI HDboolean HDAPIENTRY hdWaitForCompletion(HDSchedulerHandle hHandle,
                                               HDWaitCode param);
/* seconds since the current tick began */
HDAPI HDdouble HDAPIENTRY hdGetSchedulerTimeStamp(void);

HD_EXTERN_C_END

#endif /* VMHAPTICS_HD_SCHEDULER_H_ */
